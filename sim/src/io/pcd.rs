//! PCD (Point Cloud Library) files: an organized writer and a reader for PCD v0.7 files.
//!
//! The writer stores the whole grid (`WIDTH` = columns, `HEIGHT` = rows x planes, NaN x y z where
//! there is no return), so `POINTS` always equals `WIDTH * HEIGHT` and the data. Fields, in order:
//! `x y z` (F4, vehicle frame, metres), `intensity` (F4, `[0, 1]`), `ring` (U2), `time` (F8,
//! seconds), `label` (U4: the SemanticKITTI class, U4 as PCL's `PointXYZL` expects), `instance`
//! (U4), `ground` (U1, 0/1), `range` (F4, metres), `sensor` (U1), `echo` (U1), `column` (U4) and
//! `normal_x normal_y normal_z` (F4). A comment line `# groundtruth rows=R planes=P` lets our
//! reader restore multi-echo grids; other tools ignore it.
//!
//! The reader accepts `ascii`, `binary` and `binary_compressed` (LZF, field-major) data,
//! any field order, types F/I/U of sizes 1/2/4/8 and COUNT > 1 (only the first element is read).
//! Organized files (`HEIGHT > 1`) become a `HEIGHT x WIDTH` grid, unorganized ones a `1 x N` grid.
//! Fields the file lacks get defaults: ring = row, column = column, sensor 0, time 0, label 0,
//! instance 0, ground = whether the label is a ground class, range = distance from the origin.

use std::io::Write;
use std::path::Path;

use glam::Vec3;

use super::read_util::{Scalar, header_lines, read_file};
use crate::cloud::OrderedCloud;
use crate::error::{Result, SimError};
use crate::scene::SemanticClass;

/// Field names, type letters and sizes the writer emits, in order.
const WRITE_FIELDS: [(&str, char, usize); 16] = [
    ("x", 'F', 4),
    ("y", 'F', 4),
    ("z", 'F', 4),
    ("intensity", 'F', 4),
    ("ring", 'U', 2),
    ("time", 'F', 8),
    ("label", 'U', 4),
    ("instance", 'U', 4),
    ("ground", 'U', 1),
    ("range", 'F', 4),
    ("sensor", 'U', 1),
    ("echo", 'U', 1),
    ("column", 'U', 4),
    ("normal_x", 'F', 4),
    ("normal_y", 'F', 4),
    ("normal_z", 'F', 4),
];

/// Bytes per point of the binary records the writer emits.
pub const RECORD_BYTES: usize = 4 * 4 + 2 + 8 + 4 + 4 + 1 + 4 + 1 + 1 + 4 + 3 * 4;

fn header_text(cloud: &OrderedCloud, ascii: bool) -> String {
    let mut h = String::with_capacity(512);
    h.push_str("# .PCD v0.7 - Point Cloud Data file format\n");
    h.push_str(&format!("# groundtruth rows={} planes={}\n", cloud.rows, cloud.planes));
    h.push_str("VERSION 0.7\nFIELDS");
    for (name, _, _) in WRITE_FIELDS {
        h.push(' ');
        h.push_str(name);
    }
    h.push_str("\nSIZE");
    for (_, _, size) in WRITE_FIELDS {
        h.push_str(&format!(" {size}"));
    }
    h.push_str("\nTYPE");
    for (_, ty, _) in WRITE_FIELDS {
        h.push(' ');
        h.push(ty);
    }
    h.push_str("\nCOUNT");
    for _ in WRITE_FIELDS {
        h.push_str(" 1");
    }
    let height = cloud.rows * cloud.planes;
    h.push_str(&format!(
        "\nWIDTH {}\nHEIGHT {}\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {}\nDATA {}\n",
        cloud.cols,
        height,
        cloud.cols * height,
        if ascii { "ascii" } else { "binary" }
    ));
    h
}

/// Encodes the organized PCD file of `cloud` (binary, or ASCII when `ascii`).
pub fn encode(cloud: &OrderedCloud, ascii: bool) -> Result<Vec<u8>> {
    cloud.check_consistent().map_err(|m| SimError::invalid("cloud", m, "every field planes*rows*cols long"))?;
    let n = cloud.len();
    let header = header_text(cloud, ascii);
    let mut out = Vec::with_capacity(header.len() + n * if ascii { 120 } else { RECORD_BYTES });
    out.extend_from_slice(header.as_bytes());
    for i in 0..n {
        let p = cloud.point_in_vehicle[i];
        let nrm = cloud.normal[i];
        if ascii {
            // `{}` prints the shortest text that parses back to the same float.
            let _ = writeln!(
                out,
                "{} {} {} {} {} {} {} {} {} {} {} {} {} {} {} {}",
                p.x,
                p.y,
                p.z,
                cloud.intensity[i],
                cloud.ring[i],
                cloud.time_s[i],
                cloud.label[i].0,
                cloud.instance[i],
                u8::from(cloud.ground[i]),
                cloud.range_m[i],
                cloud.sensor[i],
                cloud.echo[i],
                cloud.column[i],
                nrm.x,
                nrm.y,
                nrm.z
            );
        } else {
            let mut rec = [0u8; RECORD_BYTES];
            rec[0..4].copy_from_slice(&p.x.to_le_bytes());
            rec[4..8].copy_from_slice(&p.y.to_le_bytes());
            rec[8..12].copy_from_slice(&p.z.to_le_bytes());
            rec[12..16].copy_from_slice(&cloud.intensity[i].to_le_bytes());
            rec[16..18].copy_from_slice(&cloud.ring[i].to_le_bytes());
            rec[18..26].copy_from_slice(&cloud.time_s[i].to_le_bytes());
            rec[26..30].copy_from_slice(&u32::from(cloud.label[i].0).to_le_bytes());
            rec[30..34].copy_from_slice(&cloud.instance[i].to_le_bytes());
            rec[34] = u8::from(cloud.ground[i]);
            rec[35..39].copy_from_slice(&cloud.range_m[i].to_le_bytes());
            rec[39] = cloud.sensor[i];
            rec[40] = cloud.echo[i];
            rec[41..45].copy_from_slice(&cloud.column[i].to_le_bytes());
            rec[45..49].copy_from_slice(&nrm.x.to_le_bytes());
            rec[49..53].copy_from_slice(&nrm.y.to_le_bytes());
            rec[53..57].copy_from_slice(&nrm.z.to_le_bytes());
            out.extend_from_slice(&rec);
        }
    }
    Ok(out)
}

/// Writes `cloud` as an organized PCD file at `path` (atomically). Returns the point count
/// (`WIDTH * HEIGHT`, every cell).
pub fn write(path: &Path, cloud: &OrderedCloud, ascii: bool) -> Result<usize> {
    let bytes = encode(cloud, ascii)?;
    super::atomic::write_bytes_atomic(path, &bytes)?;
    Ok(cloud.len())
}

/// Reads a PCD file into an ordered cloud (see the module docs for the mapping).
pub fn read(path: &Path) -> Result<OrderedCloud> {
    let bytes = read_file(path)?;
    read_bytes(path, &bytes)
}

/// The fields the reader understands.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Slot {
    X,
    Y,
    Z,
    Intensity,
    Ring,
    Time,
    Label,
    Instance,
    Ground,
    Range,
    Sensor,
    Echo,
    Column,
    Nx,
    Ny,
    Nz,
}

const SLOTS: usize = 16;

fn slot_of(name: &str) -> Option<Slot> {
    Some(match name {
        "x" => Slot::X,
        "y" => Slot::Y,
        "z" => Slot::Z,
        "intensity" => Slot::Intensity,
        "ring" => Slot::Ring,
        "time" | "timestamp" => Slot::Time,
        "label" => Slot::Label,
        "instance" => Slot::Instance,
        "ground" => Slot::Ground,
        "range" => Slot::Range,
        "sensor" => Slot::Sensor,
        "echo" => Slot::Echo,
        "column" => Slot::Column,
        "normal_x" => Slot::Nx,
        "normal_y" => Slot::Ny,
        "normal_z" => Slot::Nz,
        _ => return None,
    })
}

#[derive(Clone, Copy)]
struct FieldPos {
    scalar: Scalar,
    /// Byte offset within a binary record.
    offset: usize,
    /// Token index within an ASCII line.
    token: usize,
}

#[derive(PartialEq, Eq)]
enum DataKind {
    Ascii,
    Binary,
    /// LZF-compressed, field-major (PCL's `binary_compressed`).
    Compressed,
}

struct Header {
    slots: [Option<FieldPos>; SLOTS],
    width: usize,
    height: usize,
    points: usize,
    record_bytes: usize,
    tokens: usize,
    data: DataKind,
    data_start: usize,
    /// `(rows, planes)` from our comment line.
    grid: Option<(usize, usize)>,
    /// `(byte offset, byte width)` of every field within a record, in file order.
    field_spans: Vec<(usize, usize)>,
}

fn parse_usize(path: &Path, key: &str, v: Option<&&str>) -> Result<usize> {
    v.and_then(|s| s.parse::<usize>().ok())
        .ok_or_else(|| SimError::bad_file(path, format!("PCD header: {key} needs a non-negative integer")))
}

fn parse_header(path: &Path, bytes: &[u8]) -> Result<Header> {
    let bad = |m: String| SimError::bad_file(path, m);
    let (lines, data_start) =
        header_lines(bytes, 1 << 16, |l| l.split_whitespace().next().is_some_and(|k| k.eq_ignore_ascii_case("DATA")))
            .ok_or_else(|| bad("not a PCD file: no `DATA` line in the first 64 KiB".into()))?;
    let mut fields: Vec<String> = Vec::new();
    let mut sizes: Vec<usize> = Vec::new();
    let mut types: Vec<char> = Vec::new();
    let mut counts: Option<Vec<usize>> = None;
    let (mut width, mut height, mut points) = (None, None, None);
    let mut data = None;
    let mut grid = None;
    for line in &lines {
        let words: Vec<&str> = line.split_whitespace().collect();
        let Some(key) = words.first() else { continue };
        let rest = &words[1..];
        if key.starts_with('#') {
            if words.get(1) == Some(&"groundtruth") {
                let get = |k: &str| words.iter().find_map(|w| w.strip_prefix(k).and_then(|v| v.parse::<usize>().ok()));
                if let (Some(r), Some(p)) = (get("rows="), get("planes=")) {
                    grid = Some((r, p));
                }
            }
            continue;
        }
        match key.to_ascii_uppercase().as_str() {
            "VERSION" | "VIEWPOINT" => {}
            "FIELDS" | "COLUMNS" => fields = rest.iter().map(|s| s.to_string()).collect(),
            "SIZE" => {
                sizes = rest
                    .iter()
                    .map(|s| s.parse::<usize>().map_err(|_| bad(format!("PCD header: bad SIZE `{s}`"))))
                    .collect::<Result<_>>()?
            }
            "TYPE" => {
                types = rest
                    .iter()
                    .map(|s| match s.to_ascii_uppercase().as_str() {
                        "F" => Ok('F'),
                        "U" => Ok('U'),
                        "I" => Ok('I'),
                        _ => Err(bad(format!("PCD header: bad TYPE `{s}` (allowed: F, U, I)"))),
                    })
                    .collect::<Result<_>>()?
            }
            "COUNT" => {
                counts = Some(
                    rest.iter()
                        .map(|s| match s.parse::<usize>() {
                            Ok(c) if (1..=4096).contains(&c) => Ok(c),
                            _ => Err(bad(format!("PCD header: bad COUNT `{s}` (allowed: 1 ..= 4096)"))),
                        })
                        .collect::<Result<_>>()?,
                )
            }
            "WIDTH" => width = Some(parse_usize(path, "WIDTH", rest.first())?),
            "HEIGHT" => height = Some(parse_usize(path, "HEIGHT", rest.first())?),
            "POINTS" => points = Some(parse_usize(path, "POINTS", rest.first())?),
            "DATA" => {
                data = Some(match rest.first().map(|s| s.to_ascii_lowercase()) {
                    Some(s) if s == "ascii" => DataKind::Ascii,
                    Some(s) if s == "binary" => DataKind::Binary,
                    Some(s) if s == "binary_compressed" => DataKind::Compressed,
                    other => return Err(bad(format!("PCD header: unknown DATA `{}`", other.unwrap_or_default()))),
                })
            }
            other => return Err(bad(format!("PCD header: unknown keyword `{other}`"))),
        }
    }
    if fields.is_empty() {
        return Err(bad("PCD header: no FIELDS".into()));
    }
    let counts = counts.unwrap_or_else(|| vec![1; fields.len()]);
    if sizes.len() != fields.len() || types.len() != fields.len() || counts.len() != fields.len() {
        return Err(bad(format!(
            "PCD header: {} FIELDS but {} SIZE, {} TYPE and {} COUNT entries",
            fields.len(),
            sizes.len(),
            types.len(),
            counts.len()
        )));
    }
    let width = width.ok_or_else(|| bad("PCD header: no WIDTH".into()))?;
    let height = height.unwrap_or(1);
    let declared = width.checked_mul(height).ok_or_else(|| bad("PCD header: WIDTH * HEIGHT overflows".into()))?;
    let points = points.unwrap_or(declared);
    if points != declared {
        return Err(bad(format!("PCD header: POINTS {points} but WIDTH {width} x HEIGHT {height} = {declared}")));
    }
    let data = data.ok_or_else(|| bad("PCD header: no DATA".into()))?;
    let mut slots = [None; SLOTS];
    let (mut offset, mut token) = (0usize, 0usize);
    let mut field_spans = Vec::with_capacity(fields.len());
    for k in 0..fields.len() {
        let scalar = match (types[k], sizes[k]) {
            ('F', 4 | 8) => Scalar::F(sizes[k]),
            ('U', 1 | 2 | 4 | 8) => Scalar::U(sizes[k]),
            ('I', 1 | 2 | 4 | 8) => Scalar::I(sizes[k]),
            (t, s) => return Err(bad(format!("PCD header: field `{}` has unsupported TYPE {t} SIZE {s}", fields[k]))),
        };
        if let Some(slot) = slot_of(&fields[k]) {
            slots[slot as usize].get_or_insert(FieldPos { scalar, offset, token });
        }
        field_spans.push((offset, sizes[k] * counts[k]));
        offset += sizes[k] * counts[k];
        token += counts[k];
    }
    for (slot, name) in [(Slot::X, "x"), (Slot::Y, "y"), (Slot::Z, "z")] {
        if slots[slot as usize].is_none() {
            return Err(bad(format!("PCD header: no `{name}` field")));
        }
    }
    Ok(Header {
        slots,
        width,
        height,
        points,
        record_bytes: offset,
        tokens: token,
        data,
        data_start,
        grid,
        field_spans,
    })
}

/// Decompresses PCL's `binary_compressed` data (u32 compressed size, u32 uncompressed size, LZF
/// data holding each field's values for all points in turn) into point-major records.
fn decompress_fields(path: &Path, h: &Header, data: &[u8]) -> Result<Vec<u8>> {
    let bad = |m: String| SimError::bad_file(path, format!("PCD binary_compressed: {m}"));
    let word = |k: usize| data.get(k..k + 4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize);
    let (Some(packed), Some(unpacked)) = (word(0), word(4)) else {
        return Err(bad("data shorter than its 8-byte size prefix".into()));
    };
    let need = h.points.checked_mul(h.record_bytes).ok_or_else(|| bad("data size overflows".into()))?;
    if unpacked != need {
        return Err(bad(format!(
            "uncompressed size {unpacked} but {} points of {} bytes need {need}",
            h.points, h.record_bytes
        )));
    }
    let lzf = data.get(8..8 + packed).ok_or_else(|| {
        bad(format!("compressed size {packed} but the file holds {} bytes after the prefix", data.len() - 8))
    })?;
    // LZF expands at most ~132 times (a 2-byte back-reference of up to 264 bytes).
    if unpacked > lzf.len().saturating_mul(140) + 64 {
        return Err(bad(format!("{packed} compressed bytes cannot expand to {unpacked}")));
    }
    let fields = super::lzf::decompress(lzf, unpacked).map_err(bad)?;
    // Field-major -> point-major: field k (`width` bytes per point) starts at `points * offset_k`.
    let mut out = vec![0u8; need];
    for (offset, width) in &h.field_spans {
        let src = &fields[h.points * offset..h.points * (offset + width)];
        for (i, chunk) in src.chunks_exact(*width).enumerate() {
            out[i * h.record_bytes + offset..i * h.record_bytes + offset + width].copy_from_slice(chunk);
        }
    }
    Ok(out)
}

/// Parses PCD `bytes` (read from `path`, named in errors) into an ordered cloud.
pub fn read_bytes(path: &Path, bytes: &[u8]) -> Result<OrderedCloud> {
    let h = parse_header(path, bytes)?;
    let bad = |m: String| SimError::bad_file(path, m);
    let decompressed;
    let body = match h.data {
        DataKind::Compressed => {
            decompressed = decompress_fields(path, &h, &bytes[h.data_start..])?;
            &decompressed[..]
        }
        _ => &bytes[h.data_start..],
    };
    // Check the declared size against the data before allocating anything of that size.
    let mut ascii_lines: Vec<&[u8]> = Vec::new();
    match h.data {
        DataKind::Binary | DataKind::Compressed => {
            let need = h.points.checked_mul(h.record_bytes).ok_or_else(|| bad("PCD: data size overflows".into()))?;
            if body.len() != need {
                return Err(bad(format!(
                    "PCD header declares {} points of {} bytes ({need} bytes) but the file holds {} data bytes",
                    h.points,
                    h.record_bytes,
                    body.len()
                )));
            }
        }
        DataKind::Ascii => {
            ascii_lines = body.split(|&b| b == b'\n').filter(|l| l.iter().any(|b| !b.is_ascii_whitespace())).collect();
            if ascii_lines.len() != h.points {
                return Err(bad(format!(
                    "PCD header declares {} points but the ASCII data has {} lines",
                    h.points,
                    ascii_lines.len()
                )));
            }
        }
    }
    let (rows, cols, planes) = if h.height > 1 {
        match h.grid {
            Some((r, p)) if r > 0 && p > 0 && r.checked_mul(p) == Some(h.height) => (r, h.width, p),
            _ => (h.height, h.width, 1),
        }
    } else {
        (1, h.points, 1)
    };
    let mut cloud = OrderedCloud::empty(rows, cols, planes);
    let mut vals = [f64::NAN; SLOTS];
    let mut tokens: Vec<&str> = Vec::with_capacity(h.tokens);
    for i in 0..h.points {
        match h.data {
            DataKind::Binary | DataKind::Compressed => {
                let rec = &body[i * h.record_bytes..(i + 1) * h.record_bytes];
                for (v, pos) in vals.iter_mut().zip(h.slots.iter()) {
                    *v = pos.and_then(|p| p.scalar.decode(&rec[p.offset..], false)).unwrap_or(f64::NAN);
                }
            }
            DataKind::Ascii => {
                let line =
                    std::str::from_utf8(ascii_lines[i]).map_err(|_| bad(format!("PCD ASCII point {i} is not text")))?;
                tokens.clear();
                tokens.extend(line.split_whitespace());
                if tokens.len() != h.tokens {
                    return Err(bad(format!(
                        "PCD ASCII point {i} has {} values, header needs {}",
                        tokens.len(),
                        h.tokens
                    )));
                }
                for (v, pos) in vals.iter_mut().zip(h.slots.iter()) {
                    *v = match pos {
                        Some(p) => tokens[p.token]
                            .parse::<f64>()
                            .map_err(|_| bad(format!("PCD ASCII point {i}: `{}` is not a number", tokens[p.token])))?,
                        None => f64::NAN,
                    };
                }
            }
        }
        let has = |s: Slot| h.slots[s as usize].is_some();
        let v = |s: Slot| vals[s as usize];
        let p = Vec3::new(v(Slot::X) as f32, v(Slot::Y) as f32, v(Slot::Z) as f32);
        let hit = p.is_finite();
        let (row_in_plane, col) = ((i / cols.max(1)) % rows.max(1), i % cols.max(1));
        cloud.point_in_vehicle[i] = if hit { p } else { Vec3::NAN };
        cloud.range_m[i] = match (hit, has(Slot::Range)) {
            (false, _) => f32::NAN,
            (true, true) => v(Slot::Range) as f32,
            (true, false) => p.length(),
        };
        cloud.intensity[i] = if has(Slot::Intensity) { v(Slot::Intensity) as f32 } else { 0.0 };
        cloud.ring[i] = if has(Slot::Ring) { v(Slot::Ring) as u16 } else { row_in_plane as u16 };
        cloud.column[i] = if has(Slot::Column) { v(Slot::Column) as u32 } else { col as u32 };
        cloud.sensor[i] = if has(Slot::Sensor) { v(Slot::Sensor) as u8 } else { 0 };
        cloud.time_s[i] = if has(Slot::Time) { v(Slot::Time) } else { 0.0 };
        cloud.echo[i] = if has(Slot::Echo) { v(Slot::Echo) as u8 } else { (i / (rows * cols).max(1)) as u8 };
        let label = SemanticClass(if has(Slot::Label) { v(Slot::Label) as u16 } else { 0 });
        cloud.label[i] = label;
        cloud.instance[i] = if has(Slot::Instance) { v(Slot::Instance) as u32 } else { 0 };
        cloud.ground[i] = if has(Slot::Ground) { v(Slot::Ground) != 0.0 } else { hit && label.is_ground() };
        if has(Slot::Nx) && has(Slot::Ny) && has(Slot::Nz) {
            let n = Vec3::new(v(Slot::Nx) as f32, v(Slot::Ny) as f32, v(Slot::Nz) as f32);
            cloud.normal[i] = if n.is_finite() { n } else { Vec3::ZERO };
        }
    }
    Ok(cloud)
}
