//! The PCD header: fields, sizes, types, counts, grid size and data kind, checked against each
//! other; and PCL's `binary_compressed` body turned back into point-major records.

use std::path::Path;

use super::super::read_util::{Scalar, header_lines};
use crate::error::{Result, SimError};

/// The fields the reader understands.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Slot {
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

pub(super) const SLOTS: usize = 16;

pub(super) fn slot_of(name: &str) -> Option<Slot> {
    Some(match name {
        "x" => Slot::X,
        "y" => Slot::Y,
        "z" => Slot::Z,
        "intensity" => Slot::Intensity,
        // `channel`: the laser's index in nebula's Hesai and RoboSense clouds (ROS 2 drivers).
        "ring" | "channel" => Slot::Ring,
        "time" | "timestamp" | "t" => Slot::Time,
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
pub(super) struct FieldPos {
    pub(super) scalar: Scalar,
    /// Byte offset within a binary record.
    pub(super) offset: usize,
    /// Token index within an ASCII line.
    pub(super) token: usize,
}

#[derive(PartialEq, Eq)]
pub(crate) enum DataKind {
    Ascii,
    Binary,
    /// LZF-compressed, field-major (PCL's `binary_compressed`).
    Compressed,
}

pub(crate) struct Header {
    pub(super) slots: [Option<FieldPos>; SLOTS],
    pub(super) width: usize,
    pub(super) height: usize,
    pub(super) points: usize,
    pub(super) record_bytes: usize,
    pub(super) tokens: usize,
    pub(super) data: DataKind,
    pub(super) data_start: usize,
    /// `(rows, planes)` from our comment line.
    pub(super) grid: Option<(usize, usize)>,
    /// `(byte offset, byte width)` of every field within a record, in file order.
    pub(super) field_spans: Vec<(usize, usize)>,
}

fn parse_usize(path: &Path, key: &str, v: Option<&&str>) -> Result<usize> {
    v.and_then(|s| s.parse::<usize>().ok())
        .ok_or_else(|| SimError::bad_file(path, format!("PCD header: {key} needs a non-negative integer")))
}

pub(super) fn parse_header(path: &Path, bytes: &[u8]) -> Result<Header> {
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
            if let Some(g) = grid_of_comment(line) {
                grid = Some(g);
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
    let fields: Vec<FieldDecl> = fields
        .into_iter()
        .zip(types)
        .zip(sizes)
        .zip(counts)
        .map(|(((name, letter), size), count)| FieldDecl { name, letter, size, count })
        .collect();
    layout(path, &fields, width, height, points, data, data_start, grid)
}

/// One field as a PCD header declares it (or a PointCloud2's `PointField` does): name, type letter
/// (`F`, `U`, `I`), size in bytes and count.
#[derive(Clone, Debug)]
pub(crate) struct FieldDecl {
    pub(crate) name: String,
    pub(crate) letter: char,
    pub(crate) size: usize,
    pub(crate) count: usize,
}

/// `(rows, planes)` of our own layout's `# groundtruth rows=R planes=P` comment line, if `line` is
/// one.
pub(crate) fn grid_of_comment(line: &str) -> Option<(usize, usize)> {
    let words: Vec<&str> = line.split_whitespace().collect();
    if words.first().is_none_or(|w| !w.starts_with('#')) || words.get(1) != Some(&"groundtruth") {
        return None;
    }
    let get = |k: &str| words.iter().find_map(|w| w.strip_prefix(k).and_then(|v| v.parse::<usize>().ok()));
    match (get("rows="), get("planes=")) {
        (Some(r), Some(p)) => Some((r, p)),
        _ => None,
    }
}

/// The header of records laid out as `fields` say, in that order (`points` of them, `width x
/// height` declared): where each field the reader understands lies in a record, checked (types
/// and sizes the reader decodes, `x y z` present). The one place a record layout is decided, for
/// PCD files and PointCloud2 messages alike.
#[allow(clippy::too_many_arguments)]
pub(crate) fn layout(
    path: &Path,
    fields: &[FieldDecl],
    width: usize,
    height: usize,
    points: usize,
    data: DataKind,
    data_start: usize,
    grid: Option<(usize, usize)>,
) -> Result<Header> {
    let bad = |m: String| SimError::bad_file(path, m);
    let mut slots = [None; SLOTS];
    let (mut offset, mut token) = (0usize, 0usize);
    let mut field_spans = Vec::with_capacity(fields.len());
    for f in fields {
        let scalar = match (f.letter, f.size) {
            ('F', 4 | 8) => Scalar::F(f.size),
            ('U', 1 | 2 | 4 | 8) => Scalar::U(f.size),
            ('I', 1 | 2 | 4 | 8) => Scalar::I(f.size),
            (t, s) => return Err(bad(format!("PCD header: field `{}` has unsupported TYPE {t} SIZE {s}", f.name))),
        };
        if let Some(slot) = slot_of(&f.name) {
            let pos = FieldPos { scalar, offset, token };
            // The first field of a slot wins, but `ring` wins over its alias `channel`.
            if f.name == "ring" {
                slots[slot as usize] = Some(pos)
            } else {
                slots[slot as usize].get_or_insert(pos);
            }
        }
        field_spans.push((offset, f.size * f.count));
        offset += f.size * f.count;
        token += f.count;
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
pub(super) fn decompress_fields(path: &Path, h: &Header, data: &[u8]) -> Result<Vec<u8>> {
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
    let fields = super::super::lzf::decompress(lzf, unpacked).map_err(bad)?;
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
