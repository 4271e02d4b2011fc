//! The PCD reader: any field order, ascii / binary / binary_compressed, organized or not (see the
//! parent module's docs for the mapping of fields and the drivers' conventions).

use std::path::Path;

use glam::{Affine3A, Vec3};

use super::super::read_util::Scalar;
use super::super::read_util::read_file;
use super::decode::{Decoder, Source, field, parse_ascii};
use super::header::{DataKind, Header, Slot, decompress_fields, parse_header};
use crate::cloud::OrderedCloud;
use crate::error::{Result, SimError};

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
    let mut cloud = OrderedCloud::default();
    let info = read_bytes_into(path, bytes, &mut cloud)?;
    Ok((cloud, info))
}

/// As [`read_bytes_with_info`], into `cloud`, whose buffers are reused (a sequence of frames
/// read one after another allocates nothing once they are large enough). On an error `cloud`
/// holds no meaningful content.
pub fn read_bytes_into(path: &Path, bytes: &[u8], cloud: &mut OrderedCloud) -> Result<PcdInfo> {
    PcdFrame::parse(path, bytes)?.read_into(cloud, None, Affine3A::IDENTITY)
}

/// A PCD file's header and data, parsed and checked against each other but not yet decoded: single
/// points can be looked at first ([`PcdFrame::point`], [`PcdFrame::ring`]), for instance to tell
/// which way up an organized file's rows are, and the whole file then read with its rows where
/// they belong and its points in the frame they belong in ([`PcdFrame::read_into`]), in one pass.
///
/// ```
/// use std::path::Path;
/// use sim::io::pcd::{PcdFrame, PcdLayout, encode_layout};
/// let mut cloud = sim::OrderedCloud::empty(2, 3, 1);
/// for (i, (p, r)) in cloud.point_in_vehicle.iter_mut().zip(&mut cloud.range_m).enumerate() {
///     *p = glam::Vec3::new(10.0, i as f32, -1.0);
///     *r = p.length();
/// }
/// let bytes = encode_layout(&cloud, PcdLayout::Ouster, false, None).unwrap();
/// let frame = PcdFrame::parse(Path::new("two_rows.pcd"), &bytes).unwrap();
/// assert_eq!(frame.shape(), (2, 3, 1));
/// // ouster-ros writes the top beam first: file row 0 holds cloud row 1.
/// assert_eq!(frame.point(0), glam::Vec3::new(10.0, 3.0, -1.0));
/// assert_eq!(frame.ring(0), Some(0));
/// // Back bottom-first, 1 m higher.
/// let mut back = sim::OrderedCloud::default();
/// let lift = glam::Affine3A::from_translation(glam::Vec3::Z);
/// frame.read_into(&mut back, Some(&[1, 0]), lift).unwrap();
/// assert_eq!(back.point_in_vehicle[0], glam::Vec3::new(10.0, 0.0, 0.0));
/// ```
pub struct PcdFrame<'a> {
    path: &'a Path,
    h: Header,
    data: Data<'a>,
    trailing_bytes: usize,
}

/// A PCD file's data, as [`Source`] reads it.
enum Data<'a> {
    /// Binary records in the file's bytes.
    Binary(&'a [u8]),
    /// Binary records decompressed from `binary_compressed` data (or gathered from a message's
    /// padded rows).
    Decompressed(Vec<u8>),
    /// ASCII values, `tokens` a point.
    Ascii(Vec<f64>),
}

impl<'a> PcdFrame<'a> {
    /// Parses the header of PCD `bytes` (read from `path`, named in errors) and checks the data
    /// against it (ASCII data is parsed here, compressed data decompressed).
    pub fn parse(path: &'a Path, bytes: &'a [u8]) -> Result<Self> {
        let h = parse_header(path, bytes)?;
        let bad = |m: String| SimError::bad_file(path, m);
        let body = &bytes[h.data_start..];
        let mut trailing_bytes = 0;
        let data = match h.data {
            // Bytes after the declared records are left unread, as PCL's reader leaves them (a
            // tool that wrote a few bytes more); [`PcdFrame::trailing_bytes`] says how many.
            DataKind::Binary => {
                let need = h.points.saturating_mul(h.record_bytes);
                trailing_bytes = body.len().saturating_sub(need);
                let body = &body[..body.len() - trailing_bytes];
                check_binary_size(path, &h, body.len())?;
                Data::Binary(body)
            }
            // Checked against the header while decompressing.
            DataKind::Compressed => Data::Decompressed(decompress_fields(path, &h, body)?),
            DataKind::Ascii => {
                let lines: Vec<&[u8]> =
                    body.split(|&b| b == b'\n').filter(|l| l.iter().any(|b| !b.is_ascii_whitespace())).collect();
                if lines.len() != h.points {
                    return Err(bad(format!(
                        "PCD header declares {} points but the ASCII data has {} lines",
                        h.points,
                        lines.len()
                    )));
                }
                let mut needed = vec![false; h.tokens];
                for p in h.slots.iter().flatten() {
                    if let Some(x) = needed.get_mut(p.token) {
                        *x = true;
                    }
                }
                Data::Ascii(parse_ascii(&lines, h.tokens, &needed, bad)?)
            }
        };
        Ok(PcdFrame { path, h, data, trailing_bytes })
    }

    /// Bytes after the records the header declares in a binary file (not read; 0 for other
    /// files).
    pub fn trailing_bytes(&self) -> usize {
        self.trailing_bytes
    }

    /// A frame of binary records laid out as `header` says, in `body` (borrowed, or owned where
    /// the records had to be gathered first): a PointCloud2 message taken as it lies
    /// ([`crate::io::ros2::pointcloud2::frame`]). `body` must hold `header.points` records.
    pub(crate) fn from_records(path: &'a Path, h: Header, body: std::borrow::Cow<'a, [u8]>) -> Result<Self> {
        check_binary_size(path, &h, body.len())?;
        let data = match body {
            std::borrow::Cow::Borrowed(b) => Data::Binary(b),
            std::borrow::Cow::Owned(v) => Data::Decompressed(v),
        };
        Ok(PcdFrame { path, h, data, trailing_bytes: 0 })
    }

    /// Which conventions the file follows (`zero_cells` is counted by [`PcdFrame::read_into`];
    /// 0 here).
    pub fn info(&self) -> PcdInfo {
        let h = &self.h;
        let integer = |s: Slot| h.slots[s as usize].is_some_and(|p| !matches!(p.scalar, Scalar::F(_)));
        PcdInfo {
            has_ring: h.slots[Slot::Ring as usize].is_some(),
            organized: h.height > 1,
            ours: h.grid.is_some(),
            zero_cells: 0,
            range_in_mm: integer(Slot::Range),
            time_in_ns: integer(Slot::Time),
        }
    }

    /// `(rows, cols, planes)` of the cloud [`PcdFrame::read_into`] makes: `HEIGHT x WIDTH` for an
    /// organized file (our own files' rows and echo planes), `1 x POINTS` for an unorganized one.
    pub fn shape(&self) -> (usize, usize, usize) {
        let h = &self.h;
        if h.height > 1 {
            match h.grid {
                Some((r, p)) if r > 0 && p > 0 && r.checked_mul(p) == Some(h.height) => (r, h.width, p),
                _ => (h.height, h.width, 1),
            }
        } else {
            (1, h.points, 1)
        }
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.h.points
    }

    /// Whether the file holds no points.
    pub fn is_empty(&self) -> bool {
        self.h.points == 0
    }

    /// Point `i` (in file order) as [`PcdFrame::read_into`] reads it with no transform: NaN where
    /// it is no return (a non-finite coordinate, or exactly (0, 0, 0)) or `i` is out of range.
    #[inline]
    pub fn point(&self, i: usize) -> Vec3 {
        if i >= self.h.points {
            return Vec3::NAN;
        }
        let (src, pos) = (self.source(), |s: Slot| self.h.slots[s as usize]);
        let mut p = [Vec3::NAN];
        if !src.f32_triple(pos(Slot::X), pos(Slot::Y), pos(Slot::Z), i..i + 1, &mut p) {
            field(&src, pos(Slot::X), i..i + 1, &mut p, |o, v| o.x = v as f32);
            field(&src, pos(Slot::Y), i..i + 1, &mut p, |o, v| o.y = v as f32);
            field(&src, pos(Slot::Z), i..i + 1, &mut p, |o, v| o.z = v as f32);
        }
        let p = p[0];
        if p.is_finite() && p != Vec3::ZERO { p } else { Vec3::NAN }
    }

    /// The `ring` field of point `i` as [`PcdFrame::read_into`] reads it, if the file has one and
    /// `i` is in range.
    pub fn ring(&self, i: usize) -> Option<u16> {
        let p = self.h.slots[Slot::Ring as usize].filter(|_| i < self.h.points)?;
        let mut r = [0u16];
        field(&self.source(), Some(p), i..i + 1, &mut r, |o, v| *o = v as u16);
        Some(r[0])
    }

    /// Decodes every point into `cloud` (its buffers reused), shaped as [`PcdFrame::shape`] says.
    /// `rows_to[k]`, where given, is the cloud row that file row `k` goes to (a permutation of the
    /// rows of a one-plane file; refused otherwise); `transform` is applied to the points (returns
    /// only) and normals as they are read, in the operations of
    /// [`crate::cloud::transform_returns`]. On an error `cloud` is unchanged.
    pub fn read_into(
        &self,
        cloud: &mut OrderedCloud,
        rows_to: Option<&[usize]>,
        transform: Affine3A,
    ) -> Result<PcdInfo> {
        let (rows, cols, planes) = self.shape();
        if let Some(to) = rows_to {
            let mut seen = vec![false; rows];
            let permutation = planes == 1
                && to.len() == rows
                && to.iter().all(|&d| d < rows && !std::mem::replace(&mut seen[d], true));
            if !permutation {
                return Err(SimError::bad_file(
                    self.path,
                    format!("rows_to must be a permutation of the {rows} rows of a one-plane file, got {to:?}"),
                ));
            }
        }
        let src = self.source();
        let mut decoder = Decoder::start(&self.h, self.info(), (rows, cols, planes), rows_to, transform, cloud);
        match rows_to {
            Some(to) => {
                for (k, &d) in to.iter().enumerate() {
                    decoder.decode(&src, k * cols..(k + 1) * cols, d * cols, cloud);
                }
            }
            None => decoder.decode(&src, 0..self.h.points, 0, cloud),
        }
        Ok(decoder.info)
    }

    /// The data as the decoder reads it.
    fn source(&self) -> Source<'_> {
        let record = self.h.record_bytes;
        match &self.data {
            Data::Binary(body) => Source::Binary { body, record },
            Data::Decompressed(records) => Source::Binary { body: records, record },
            Data::Ascii(values) => Source::Ascii { values, tokens: self.h.tokens },
        }
    }
}

/// Refuses binary data of `data_bytes` that do not hold exactly the header's points.
fn check_binary_size(path: &Path, h: &Header, data_bytes: usize) -> Result<()> {
    let bad = |m: String| SimError::bad_file(path, m);
    let need = h.points.checked_mul(h.record_bytes).ok_or_else(|| bad("PCD: data size overflows".into()))?;
    if data_bytes != need {
        return Err(bad(format!(
            "PCD header declares {} points of {} bytes ({need} bytes) but the file holds {data_bytes} data bytes",
            h.points, h.record_bytes
        )));
    }
    Ok(())
}
