//! A small general PLY parser (ASCII, binary little- and big-endian) shared by the point-cloud
//! reader ([`super::ply`]) and the scene-mesh reader ([`crate::scene::ply`]).
//!
//! It parses the header into elements and properties, checks that the data can hold what the
//! header declares (so no allocation is sized from an unchecked header), and walks the rows of
//! each element, handing the caller each row's scalar values and the items of its first list.

use std::path::Path;

use super::read_util::{Scalar, header_lines};
use crate::error::{Result, SimError};

/// How a property is stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PlyKind {
    /// One scalar.
    Scalar(Scalar),
    /// A list: a count of type `count`, then that many `item`s.
    List {
        /// Type of the count.
        count: Scalar,
        /// Type of each item.
        item: Scalar,
    },
}

/// One property of an element.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PlyProperty {
    /// Property name (`x`, `vertex_indices`, ...).
    pub name: String,
    /// Storage type.
    pub kind: PlyKind,
}

/// One element (`vertex`, `face`, ...) with its row count and properties.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PlyElement {
    /// Element name.
    pub name: String,
    /// Number of rows.
    pub count: usize,
    /// Properties in file order.
    pub properties: Vec<PlyProperty>,
}

impl PlyElement {
    /// Index of the scalar property named `name`, if any.
    pub fn scalar_index(&self, name: &str) -> Option<usize> {
        self.properties.iter().position(|p| p.name == name && matches!(p.kind, PlyKind::Scalar(_)))
    }
}

/// Data encoding of a PLY file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PlyEncoding {
    /// Whitespace-separated text.
    Ascii,
    /// Binary little-endian.
    BinaryLe,
    /// Binary big-endian.
    BinaryBe,
}

/// A parsed PLY header.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PlyHeader {
    /// Data encoding.
    pub encoding: PlyEncoding,
    /// Elements in file order.
    pub elements: Vec<PlyElement>,
    /// Byte offset where the data begins.
    pub data_start: usize,
}

fn scalar_type(name: &str) -> Option<Scalar> {
    Some(match name {
        "char" | "int8" => Scalar::I(1),
        "uchar" | "uint8" => Scalar::U(1),
        "short" | "int16" => Scalar::I(2),
        "ushort" | "uint16" => Scalar::U(2),
        "int" | "int32" => Scalar::I(4),
        "uint" | "uint32" => Scalar::U(4),
        "float" | "float32" => Scalar::F(4),
        "double" | "float64" => Scalar::F(8),
        _ => return None,
    })
}

/// Parses the header of PLY `bytes` and checks the declared counts against the data length.
pub fn parse_header(path: &Path, bytes: &[u8]) -> Result<PlyHeader> {
    let bad = |m: String| SimError::bad_file(path, m);
    if !bytes.starts_with(b"ply") {
        return Err(bad("not a PLY file: it does not start with `ply`".into()));
    }
    let (lines, data_start) = header_lines(bytes, 1 << 16, |l| l.trim() == "end_header")
        .ok_or_else(|| bad("PLY header: no `end_header` line in the first 64 KiB".into()))?;
    let mut encoding = None;
    let mut elements: Vec<PlyElement> = Vec::new();
    for (k, line) in lines.iter().enumerate().skip(1) {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            [] | ["end_header"] => {}
            ["comment", ..] | ["obj_info", ..] => {}
            ["format", f, _version] => {
                encoding = Some(match *f {
                    "ascii" => PlyEncoding::Ascii,
                    "binary_little_endian" => PlyEncoding::BinaryLe,
                    "binary_big_endian" => PlyEncoding::BinaryBe,
                    other => return Err(bad(format!("PLY header line {}: unknown format `{other}`", k + 1))),
                })
            }
            ["element", name, count] => {
                let count = count
                    .parse::<usize>()
                    .map_err(|_| bad(format!("PLY header line {}: bad count `{count}`", k + 1)))?;
                elements.push(PlyElement { name: name.to_string(), count, properties: Vec::new() });
            }
            ["property", "list", c, i, name] => {
                let (Some(count), Some(item)) = (scalar_type(c), scalar_type(i)) else {
                    return Err(bad(format!("PLY header line {}: bad list types `{c} {i}`", k + 1)));
                };
                if matches!(count, Scalar::F(_)) {
                    return Err(bad(format!("PLY header line {}: a list count must be an integer", k + 1)));
                }
                let el = elements
                    .last_mut()
                    .ok_or_else(|| bad(format!("PLY header line {}: property before element", k + 1)))?;
                el.properties.push(PlyProperty { name: name.to_string(), kind: PlyKind::List { count, item } });
            }
            ["property", t, name] => {
                let s = scalar_type(t).ok_or_else(|| bad(format!("PLY header line {}: unknown type `{t}`", k + 1)))?;
                let el = elements
                    .last_mut()
                    .ok_or_else(|| bad(format!("PLY header line {}: property before element", k + 1)))?;
                el.properties.push(PlyProperty { name: name.to_string(), kind: PlyKind::Scalar(s) });
            }
            _ => return Err(bad(format!("PLY header line {}: cannot parse `{line}`", k + 1))),
        }
    }
    let encoding = encoding.ok_or_else(|| bad("PLY header: no `format` line".into()))?;
    // Every row needs at least this many bytes (binary) or tokens of >= 1 byte plus a separator (ASCII).
    let body = bytes.len() - data_start;
    let mut min_total: usize = 0;
    for el in &elements {
        let per_row: usize = el
            .properties
            .iter()
            .map(|p| match (encoding, p.kind) {
                (PlyEncoding::Ascii, _) => 1,
                (_, PlyKind::Scalar(s)) => s.size(),
                (_, PlyKind::List { count, .. }) => count.size(),
            })
            .sum();
        let need = el.count.checked_mul(per_row.max(1)).ok_or_else(|| bad("PLY header: sizes overflow".into()))?;
        min_total = min_total.saturating_add(need);
    }
    if min_total > body {
        return Err(bad(format!("PLY header declares at least {min_total} data bytes but the file holds {body}")));
    }
    Ok(PlyHeader { encoding, elements, data_start })
}

/// A cursor over the data section.
struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
    encoding: PlyEncoding,
}

impl Cursor<'_> {
    fn next(&mut self, s: Scalar) -> Option<f64> {
        match self.encoding {
            PlyEncoding::Ascii => {
                let b = self.bytes;
                while self.pos < b.len() && b[self.pos].is_ascii_whitespace() {
                    self.pos += 1;
                }
                let start = self.pos;
                while self.pos < b.len() && !b[self.pos].is_ascii_whitespace() {
                    self.pos += 1;
                }
                let tok = std::str::from_utf8(&b[start..self.pos]).ok()?;
                if tok.is_empty() {
                    return None;
                }
                tok.parse::<f64>().ok()
            }
            enc => {
                let v = s.decode(self.bytes.get(self.pos..)?, enc == PlyEncoding::BinaryBe)?;
                self.pos += s.size();
                Some(v)
            }
        }
    }
}

/// Walks every row of every element. For each row of the element at index `e`, calls
/// `visit(e, row, scalars, list)`: `scalars[k]` is property `k`'s value (NaN for list properties)
/// and `list` holds the items of the row's first list property. Stops with an error on truncated
/// or malformed data, or when `visit` returns one.
pub fn walk(
    path: &Path,
    bytes: &[u8],
    header: &PlyHeader,
    mut visit: impl FnMut(usize, usize, &[f64], &[f64]) -> Result<()>,
) -> Result<()> {
    let mut cur = Cursor { bytes, pos: header.data_start, encoding: header.encoding };
    let mut scalars = Vec::new();
    let mut list = Vec::new();
    for (e, el) in header.elements.iter().enumerate() {
        for row in 0..el.count {
            scalars.clear();
            list.clear();
            let mut first_list = true;
            for p in &el.properties {
                let short = || {
                    SimError::bad_file(
                        path,
                        format!(
                            "PLY data ends or is malformed in element `{}` row {row} property `{}`",
                            el.name, p.name
                        ),
                    )
                };
                match p.kind {
                    PlyKind::Scalar(s) => scalars.push(cur.next(s).ok_or_else(short)?),
                    PlyKind::List { count, item } => {
                        scalars.push(f64::NAN);
                        let n = cur.next(count).ok_or_else(short)?;
                        if !(0.0..=1.0e6).contains(&n) || n.fract() != 0.0 {
                            return Err(SimError::bad_file(
                                path,
                                format!("PLY element `{}` row {row}: list length {n} (allowed 0 ..= 1000000)", el.name),
                            ));
                        }
                        for _ in 0..n as usize {
                            let v = cur.next(item).ok_or_else(short)?;
                            if first_list {
                                list.push(v);
                            }
                        }
                        first_list = false;
                    }
                }
            }
            visit(e, row, &scalars, &list)?;
        }
    }
    Ok(())
}
