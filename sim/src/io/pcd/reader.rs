//! The PCD reader: any field order, ascii / binary / binary_compressed, organized or not (see the
//! parent module's docs for the mapping of fields and the drivers' conventions).

use std::path::Path;

use glam::Vec3;

use super::super::read_util::Scalar;
use super::super::read_util::read_file;
use super::header::{DataKind, SLOTS, Slot, decompress_fields, parse_header};
use crate::cloud::OrderedCloud;
use crate::error::{Result, SimError};
use crate::scene::SemanticClass;

/// Reads a PCD file into an ordered cloud (see the module docs for the mapping).
pub fn read(path: &Path) -> Result<OrderedCloud> {
    let bytes = read_file(path)?;
    read_bytes(path, &bytes)
}

/// What a PCD file held besides the cloud: which conventions its fields follow.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct PcdInfo {
    /// The file has a `ring` field.
    pub has_ring: bool,
    /// The file is organized (`HEIGHT > 1`).
    pub organized: bool,
    /// The file carries our `# groundtruth rows=R planes=P` line (rows bottom-first).
    pub ours: bool,
    /// Cells at exactly (0, 0, 0), read as no-returns.
    pub zero_cells: usize,
    /// The `range` field is an integer (millimetres, as ouster-ros writes it).
    pub range_in_mm: bool,
    /// The time field is an integer (nanoseconds, as ouster-ros' `t`).
    pub time_in_ns: bool,
}

/// Reads a PCD file and says which conventions it follows.
pub fn read_with_info(path: &Path) -> Result<(OrderedCloud, PcdInfo)> {
    let bytes = read_file(path)?;
    read_bytes_with_info(path, &bytes)
}

/// Parses PCD `bytes` (read from `path`, named in errors) into an ordered cloud.
pub fn read_bytes(path: &Path, bytes: &[u8]) -> Result<OrderedCloud> {
    Ok(read_bytes_with_info(path, bytes)?.0)
}

/// As [`read_bytes`], also saying which conventions the file follows.
pub fn read_bytes_with_info(path: &Path, bytes: &[u8]) -> Result<(OrderedCloud, PcdInfo)> {
    let h = parse_header(path, bytes)?;
    let integer = |s: Slot| h.slots[s as usize].is_some_and(|p| !matches!(p.scalar, Scalar::F(_)));
    let mut info = PcdInfo {
        has_ring: h.slots[Slot::Ring as usize].is_some(),
        organized: h.height > 1,
        ours: h.grid.is_some(),
        zero_cells: 0,
        range_in_mm: integer(Slot::Range),
        time_in_ns: integer(Slot::Time),
    };
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
                    *v = match pos {
                        Some(p) => decode_le(p.scalar, &rec[p.offset..]),
                        None => f64::NAN,
                    };
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
        // Drivers that keep no-return cells as zeros (ouster-ros, older velodyne): no return.
        let zero = p == Vec3::ZERO;
        info.zero_cells += usize::from(zero);
        let hit = p.is_finite() && !zero;
        let (row_in_plane, col) = ((i / cols.max(1)) % rows.max(1), i % cols.max(1));
        cloud.point_in_vehicle[i] = if hit { p } else { Vec3::NAN };
        cloud.range_m[i] = match (hit, has(Slot::Range)) {
            (false, _) => f32::NAN,
            (true, true) if info.range_in_mm => (v(Slot::Range) * 1e-3) as f32,
            (true, true) => v(Slot::Range) as f32,
            (true, false) => p.length(),
        };
        cloud.intensity[i] = if has(Slot::Intensity) { v(Slot::Intensity) as f32 } else { 0.0 };
        cloud.ring[i] = if has(Slot::Ring) { v(Slot::Ring) as u16 } else { row_in_plane as u16 };
        cloud.column[i] = if has(Slot::Column) { v(Slot::Column) as u32 } else { col as u32 };
        cloud.sensor[i] = if has(Slot::Sensor) { v(Slot::Sensor) as u8 } else { 0 };
        cloud.time_s[i] = match (has(Slot::Time), info.time_in_ns) {
            (true, true) => v(Slot::Time) * 1e-9,
            (true, false) => v(Slot::Time),
            _ => 0.0,
        };
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
    Ok((cloud, info))
}

/// One little-endian value from the start of `b`, widened to `f64` (NaN if `b` is too short): the
/// binary reader's inlined form of `Scalar::decode`.
#[inline(always)]
fn decode_le(s: Scalar, b: &[u8]) -> f64 {
    let take4 = |b: &[u8]| b.get(..4).map(|x| [x[0], x[1], x[2], x[3]]);
    match s {
        Scalar::F(4) => take4(b).map_or(f64::NAN, |x| f64::from(f32::from_le_bytes(x))),
        Scalar::U(4) => take4(b).map_or(f64::NAN, |x| f64::from(u32::from_le_bytes(x))),
        Scalar::I(4) => take4(b).map_or(f64::NAN, |x| f64::from(i32::from_le_bytes(x))),
        Scalar::U(2) => b.get(..2).map_or(f64::NAN, |x| f64::from(u16::from_le_bytes([x[0], x[1]]))),
        Scalar::I(2) => b.get(..2).map_or(f64::NAN, |x| f64::from(i16::from_le_bytes([x[0], x[1]]))),
        Scalar::U(1) => b.first().map_or(f64::NAN, |&x| f64::from(x)),
        Scalar::I(1) => b.first().map_or(f64::NAN, |&x| f64::from(x as i8)),
        other => other.decode(b, false).unwrap_or(f64::NAN),
    }
}
