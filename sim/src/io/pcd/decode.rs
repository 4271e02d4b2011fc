//! Decoding a PCD file's points into an ordered cloud: where each field lies and in which units is
//! worked out once per file ([`Decoder::start`]), then the points are decoded in blocks.

use std::ops::Range;

use glam::{Affine3A, Vec3};

use super::super::read_util::Scalar;
use super::header::{FieldPos, Header, SLOTS, Slot};
use super::reader::PcdInfo;
use crate::cloud::OrderedCloud;
use crate::error::{Result, SimError};
use crate::scene::SemanticClass;

/// Decodes a file's points into a cloud, range by range.
pub(super) struct Decoder {
    slots: [Option<FieldPos>; SLOTS],
    /// An integer `range` field: millimetres.
    mm: bool,
    /// An integer time field: nanoseconds.
    ns: bool,
    /// The file has normals (all three).
    normals: bool,
    /// Applied to the points and normals as they are read (`None`: kept in the file's frame).
    transform: Option<Affine3A>,
    /// What the file held, `zero_cells` counted as points are decoded.
    pub(super) info: PcdInfo,
}

impl Decoder {
    /// Shapes `cloud` as `(rows, cols, planes)` for the file of header `h` and writes the defaults
    /// of the fields the file lacks (every entry of every field is written once: from the file, or
    /// as a default). `rows_to[k]`: the cloud row that file row `k` goes to (a file without a
    /// `ring` field gives each cell the ring of its file row); `transform` moves the points and
    /// normals as they are read.
    pub(super) fn start(
        h: &Header,
        info: PcdInfo,
        (rows, cols, planes): (usize, usize, usize),
        rows_to: Option<&[usize]>,
        transform: Affine3A,
        cloud: &mut OrderedCloud,
    ) -> Self {
        let (rows1, cols1, plane1) = (rows.max(1), cols.max(1), (rows * cols).max(1));
        cloud.reshape(rows, cols, planes);
        debug_assert_eq!(cloud.len(), h.points);
        let has = |s: Slot| h.slots[s as usize].is_some();
        let normals = has(Slot::Nx) && has(Slot::Ny) && has(Slot::Nz);
        if !(has(Slot::X) && has(Slot::Y) && has(Slot::Z)) {
            cloud.point_in_vehicle.fill(Vec3::NAN);
        }
        if !has(Slot::Intensity) {
            cloud.intensity.fill(0.0);
        }
        // Defaults row by row (a division per point cost 1.5 ms a frame).
        if !has(Slot::Ring) {
            match rows_to {
                Some(to) => {
                    for (k, &d) in to.iter().enumerate() {
                        cloud.ring[d * cols..(d + 1) * cols].fill(k as u16);
                    }
                }
                None => {
                    for (k, rg) in cloud.ring.chunks_mut(cols1).enumerate() {
                        rg.fill((k % rows1) as u16);
                    }
                }
            }
        }
        if !has(Slot::Column) {
            for cl in cloud.column.chunks_mut(cols1) {
                cl.iter_mut().enumerate().for_each(|(c, v)| *v = c as u32);
            }
        }
        if !has(Slot::Sensor) {
            cloud.sensor.fill(0);
        }
        if !has(Slot::Time) {
            cloud.time_s.fill(0.0);
        }
        if !has(Slot::Echo) {
            for (k, e) in cloud.echo.chunks_mut(plane1).enumerate() {
                e.fill(k as u8);
            }
        }
        if !has(Slot::Label) {
            cloud.label.fill(SemanticClass::UNLABELED);
        }
        if !has(Slot::Instance) {
            cloud.instance.fill(0);
        }
        if !normals {
            cloud.normal.fill(Vec3::ZERO);
        }
        let transform = (transform != Affine3A::IDENTITY).then_some(transform);
        Decoder { slots: h.slots, mm: info.range_in_mm, ns: info.time_in_ns, normals, transform, info }
    }

    /// Decodes the points `points` (indices into the file) from `src` into the cloud's cells from
    /// `out_start` on, in blocks of [`BLOCK`] points, in each block field by field with the
    /// field's type decided once: a per-point dispatch over every field cost 3 ms of a 128 x 1024
    /// ouster-ros frame, and whole-file loops per field streamed the records from memory once per
    /// field.
    ///
    /// Compiled for AVX-512 or AVX2 where the CPU has them (the field loops run as wide as the CPU
    /// allows; plain conversions and IEEE operations, so the same values in every variant).
    pub(super) fn decode(
        &mut self,
        src: &Source<'_>,
        points: Range<usize>,
        out_start: usize,
        cloud: &mut OrderedCloud,
    ) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx512f")
            && std::arch::is_x86_feature_detected!("avx512bw")
            && std::arch::is_x86_feature_detected!("avx512vl")
            && std::arch::is_x86_feature_detected!("avx512dq")
            && std::arch::is_x86_feature_detected!("avx2")
        {
            // SAFETY: the CPU supports AVX-512 F, BW, VL and DQ and AVX2 (checked just above).
            #[allow(unsafe_code)]
            unsafe {
                return self.decode_avx512(src, points, out_start, cloud);
            }
        }
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2 (checked just above).
            #[allow(unsafe_code)]
            unsafe {
                return self.decode_avx2(src, points, out_start, cloud);
            }
        }
        self.decode_body(src, points, out_start, cloud);
    }

    /// [`Decoder::decode_body`] compiled for AVX-512 (F, BW, VL, DQ) and AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512bw,avx512vl,avx512dq,avx2")]
    fn decode_avx512(&mut self, src: &Source<'_>, points: Range<usize>, out_start: usize, cloud: &mut OrderedCloud) {
        self.decode_body(src, points, out_start, cloud);
    }

    /// [`Decoder::decode_body`] compiled for AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn decode_avx2(&mut self, src: &Source<'_>, points: Range<usize>, out_start: usize, cloud: &mut OrderedCloud) {
        self.decode_body(src, points, out_start, cloud);
    }

    /// The body of [`Decoder::decode`], inlined into each instruction-set variant.
    #[inline(always)]
    fn decode_body(&mut self, src: &Source<'_>, points: Range<usize>, out_start: usize, cloud: &mut OrderedCloud) {
        let OrderedCloud {
            point_in_vehicle,
            range_m,
            intensity,
            ring,
            column,
            sensor,
            time_s,
            echo,
            label,
            instance,
            ground,
            normal,
            ..
        } = cloud;
        let pos = |s: Slot| self.slots[s as usize];
        let (mm, ns, normals) = (self.mm, self.ns, self.normals);
        // A file's own `range` field replaces the length below (a return's mark until then).
        let has_range = pos(Slot::Range).is_some();
        for b0 in points.clone().step_by(BLOCK) {
            let b = b0..(b0 + BLOCK).min(points.end);
            let ob = b.start - points.start + out_start..b.end - points.start + out_start;
            if !src.f32_triple(pos(Slot::X), pos(Slot::Y), pos(Slot::Z), b.clone(), &mut point_in_vehicle[ob.clone()]) {
                field(src, pos(Slot::X), b.clone(), &mut point_in_vehicle[ob.clone()], |o, v| o.x = v as f32);
                field(src, pos(Slot::Y), b.clone(), &mut point_in_vehicle[ob.clone()], |o, v| o.y = v as f32);
                field(src, pos(Slot::Z), b.clone(), &mut point_in_vehicle[ob.clone()], |o, v| o.z = v as f32);
            }
            for (p, r) in point_in_vehicle[ob.clone()].iter_mut().zip(&mut range_m[ob.clone()]) {
                // Drivers that keep no-return cells as zeros (ouster-ros, older velodyne): no return.
                let zero = *p == Vec3::ZERO;
                self.info.zero_cells += usize::from(zero);
                let is_return = p.is_finite() & !zero;
                *r = if !is_return {
                    f32::NAN
                } else if has_range {
                    0.0
                } else {
                    p.length()
                };
                *p = if is_return { *p } else { Vec3::NAN };
            }
            if let Some(t) = self.transform {
                crate::cloud::transform_returns(t, &mut point_in_vehicle[ob.clone()]);
            }
            // The range of returns (no-returns keep their NaN), from the common `uint32` millimetres
            // or metres straight, else through `f64` (the same values).
            let range = |r: &mut f32, v: f64| {
                if r.is_finite() {
                    *r = if mm { (v * 1e-3) as f32 } else { v as f32 };
                }
            };
            if !src.direct::<_, u32>(pos(Slot::Range), Scalar::U(4), b.clone(), &mut range_m[ob.clone()], |r, v| {
                range(r, f64::from(v))
            }) {
                field(src, pos(Slot::Range), b.clone(), &mut range_m[ob.clone()], range);
            }
            // Typed reads where the file's type is the common one (the same values as through `f64`).
            if !src.direct::<_, f32>(
                pos(Slot::Intensity),
                Scalar::F(4),
                b.clone(),
                &mut intensity[ob.clone()],
                |o, v| *o = v,
            ) {
                field(src, pos(Slot::Intensity), b.clone(), &mut intensity[ob.clone()], |o, v| *o = v as f32);
            }
            if !src.direct::<_, u16>(pos(Slot::Ring), Scalar::U(2), b.clone(), &mut ring[ob.clone()], |o, v| *o = v) {
                field(src, pos(Slot::Ring), b.clone(), &mut ring[ob.clone()], |o, v| *o = v as u16);
            }
            field(src, pos(Slot::Column), b.clone(), &mut column[ob.clone()], |o, v| *o = v as u32);
            field(src, pos(Slot::Sensor), b.clone(), &mut sensor[ob.clone()], |o, v| *o = v as u8);
            let time = |o: &mut f64, v: f64| *o = if ns { v * 1e-9 } else { v };
            if !src.direct::<_, u32>(pos(Slot::Time), Scalar::U(4), b.clone(), &mut time_s[ob.clone()], |o, v| {
                time(o, f64::from(v))
            }) {
                field(src, pos(Slot::Time), b.clone(), &mut time_s[ob.clone()], time);
            }
            field(src, pos(Slot::Echo), b.clone(), &mut echo[ob.clone()], |o, v| *o = v as u8);
            // A label above 65535 saturates, as the `f64` cast below does.
            let label_u32 = |o: &mut SemanticClass, v: u32| *o = SemanticClass(u16::try_from(v).unwrap_or(u16::MAX));
            if !src.direct::<_, u32>(pos(Slot::Label), Scalar::U(4), b.clone(), &mut label[ob.clone()], label_u32) {
                field(src, pos(Slot::Label), b.clone(), &mut label[ob.clone()], |o, v| *o = SemanticClass(v as u16));
            }
            field(src, pos(Slot::Instance), b.clone(), &mut instance[ob.clone()], |o, v| *o = v as u32);
            for ((g, p), l) in ground[ob.clone()].iter_mut().zip(&point_in_vehicle[ob.clone()]).zip(&label[ob.clone()])
            {
                *g = !p.x.is_nan() & l.is_ground();
            }
            field(src, pos(Slot::Ground), b.clone(), &mut ground[ob.clone()], |o, v| *o = v != 0.0);
            if normals {
                field(src, pos(Slot::Nx), b.clone(), &mut normal[ob.clone()], |o, v| o.x = v as f32);
                field(src, pos(Slot::Ny), b.clone(), &mut normal[ob.clone()], |o, v| o.y = v as f32);
                field(src, pos(Slot::Nz), b.clone(), &mut normal[ob.clone()], |o, v| o.z = v as f32);
                for m in &mut normal[ob.clone()] {
                    if !m.is_finite() {
                        *m = Vec3::ZERO;
                    }
                    if let Some(t) = self.transform {
                        *m = t.transform_vector3(*m);
                    }
                }
            }
        }
    }
}

/// Points decoded together: a block's records (9 kB of a 36-byte ouster-ros record) stay in the
/// level-1 cache while each field is read from them.
const BLOCK: usize = 256;

/// Where the values of the points come from.
pub(super) enum Source<'a> {
    /// Binary records (plain or decompressed), `record` bytes each.
    Binary { body: &'a [u8], record: usize },
    /// ASCII values parsed up front, `tokens` a point.
    Ascii { values: &'a [f64], tokens: usize },
}

/// A little-endian scalar read straight from a record.
trait FromLe: Sized {
    /// Its size in bytes.
    const SIZE: usize;
    /// The value at the start of `b` (`SIZE` bytes or more).
    fn from_le(b: &[u8]) -> Self;
}

impl FromLe for f32 {
    const SIZE: usize = 4;
    #[inline(always)]
    fn from_le(b: &[u8]) -> Self {
        f32::from_le_bytes([b[0], b[1], b[2], b[3]])
    }
}

impl FromLe for u32 {
    const SIZE: usize = 4;
    #[inline(always)]
    fn from_le(b: &[u8]) -> Self {
        u32::from_le_bytes([b[0], b[1], b[2], b[3]])
    }
}

impl FromLe for u16 {
    const SIZE: usize = 2;
    #[inline(always)]
    fn from_le(b: &[u8]) -> Self {
        u16::from_le_bytes([b[0], b[1]])
    }
}

impl Source<'_> {
    /// Calls `set(&mut out[i], value)` for the field at `p` of every point of `points`, the value
    /// read as `V`, where the field is binary of type `want` (true); else does nothing (false).
    #[inline(always)]
    fn direct<T, V: FromLe>(
        &self,
        p: Option<FieldPos>,
        want: Scalar,
        points: std::ops::Range<usize>,
        out: &mut [T],
        mut set: impl FnMut(&mut T, V),
    ) -> bool {
        let (Source::Binary { body, record }, Some(p)) = (self, p) else { return false };
        if p.scalar != want || want.size() != V::SIZE || p.offset + V::SIZE > *record {
            return false;
        }
        let recs = body[points.start * record..points.end * record].chunks_exact(*record);
        for (r, o) in recs.zip(out) {
            set(o, V::from_le(&r[p.offset..]));
        }
        true
    }

    /// The points of `points` from three `float32` fields `x`, `y`, `z` of binary records, read
    /// together (one pass over the records instead of three); false where the fields are not all
    /// binary `float32` (then nothing is written).
    #[inline(always)]
    pub(super) fn f32_triple(
        &self,
        x: Option<FieldPos>,
        y: Option<FieldPos>,
        z: Option<FieldPos>,
        points: std::ops::Range<usize>,
        out: &mut [Vec3],
    ) -> bool {
        let (Source::Binary { body, record }, Some(x), Some(y), Some(z)) = (self, x, y, z) else { return false };
        if [x, y, z].iter().any(|p| p.scalar != Scalar::F(4) || p.offset + 4 > *record) {
            return false;
        }
        let f = |r: &[u8], at: usize| f32::from_le(&r[at..at + 4]);
        for (r, o) in body[points.start * record..points.end * record].chunks_exact(*record).zip(out) {
            *o = Vec3::new(f(r, x.offset), f(r, y.offset), f(r, z.offset));
        }
        true
    }

    /// Calls `set(&mut out[i], value)` for the field at `p` of every point of `points` (`out` holds
    /// their slots, in order); the field's type is matched once, outside the loop, and records and
    /// slots are zipped (no index checks).
    #[inline(always)]
    fn each<T>(&self, p: FieldPos, points: std::ops::Range<usize>, out: &mut [T], mut set: impl FnMut(&mut T, f64)) {
        match self {
            Source::Ascii { values, tokens } => {
                for (i, o) in points.zip(out) {
                    set(o, values[i * tokens + p.token]);
                }
            }
            Source::Binary { body, record } => {
                let record = (*record).max(1);
                let recs = body[points.start * record..points.end * record].chunks_exact(record);
                let at = p.offset;
                match p.scalar {
                    Scalar::F(4) => recs
                        .zip(out)
                        .for_each(|(r, o)| set(o, le4(r, at).map_or(f64::NAN, |b| f64::from(f32::from_le_bytes(b))))),
                    Scalar::U(4) => recs
                        .zip(out)
                        .for_each(|(r, o)| set(o, le4(r, at).map_or(f64::NAN, |b| f64::from(u32::from_le_bytes(b))))),
                    Scalar::U(2) => recs.zip(out).for_each(|(r, o)| {
                        set(o, r.get(at..at + 2).map_or(f64::NAN, |x| f64::from(u16::from_le_bytes([x[0], x[1]]))))
                    }),
                    s => recs.zip(out).for_each(|(r, o)| set(o, decode_le(s, r.get(at..).unwrap_or(&[])))),
                }
            }
        }
    }
}

/// [`Source::each`] for the field at `p`, if the file has it.
#[inline(always)]
pub(super) fn field<T>(
    src: &Source<'_>,
    p: Option<FieldPos>,
    points: std::ops::Range<usize>,
    out: &mut [T],
    set: impl FnMut(&mut T, f64),
) {
    if let Some(p) = p {
        src.each(p, points, out, set);
    }
}

/// The 4 bytes at `at` of record `r`, if it holds them.
#[inline(always)]
fn le4(r: &[u8], at: usize) -> Option<[u8; 4]> {
    r.get(at..at + 4).map(|x| [x[0], x[1], x[2], x[3]])
}

/// The values of ASCII `lines`, `tokens` a line (the tokens of `needed` parsed, the others NaN),
/// refused with the point and token named.
pub(super) fn parse_ascii(
    lines: &[&[u8]],
    tokens: usize,
    needed: &[bool],
    bad: impl Fn(String) -> SimError,
) -> Result<Vec<f64>> {
    let mut values = Vec::with_capacity(lines.len() * tokens);
    let mut line_tokens: Vec<&str> = Vec::with_capacity(tokens);
    for (i, raw) in lines.iter().enumerate() {
        let line = std::str::from_utf8(raw).map_err(|_| bad(format!("PCD ASCII point {i} is not text")))?;
        line_tokens.clear();
        line_tokens.extend(line.split_whitespace());
        if line_tokens.len() != tokens {
            return Err(bad(format!("PCD ASCII point {i} has {} values, header needs {tokens}", line_tokens.len())));
        }
        for (t, &need) in line_tokens.iter().zip(needed) {
            values.push(if need {
                t.parse::<f64>().map_err(|_| bad(format!("PCD ASCII point {i}: `{t}` is not a number")))?
            } else {
                f64::NAN
            });
        }
    }
    Ok(values)
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
