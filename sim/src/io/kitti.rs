//! KITTI / SemanticKITTI files: `frame_NNNNNN.bin` (float32 `x y z intensity` per return, in scan
//! order as a real HDL-64E's KITTI files are: see [`scan_order`]), `frame_NNNNNN.label` (uint32
//! per return: semantic class in the low 16 bits,
//! instance id in the high 16 bits; instance ids above 65535 keep their low 16 bits; the class is
//! `SemanticClass::semantic_kitti_id`, so our bush class 73 is written as 70 vegetation) and, for a
//! single-sensor rig, `frame_NNNNNN.calib.txt` with one line `Tr: r00 r01 r02 t0 r10 ... t2`, the
//! 3 x 4 row-major `vehicle_from_sensor` transform (points in the `.bin` are then in the sensor
//! frame, as KITTI's are; multiply by `Tr` to get vehicle-frame points). Intensity is in `[0, 1]`.
//!
//! The reader takes a `.bin` and optionally its `.label` and returns a `1 x N` cloud in file order
//! (`range_m` = distance from the origin, `column` = point index, ground = the label is a ground
//! class). It refuses a file whose length is not a whole number of records and a `.label` of
//! another length; points with NaN or infinite coordinates are kept as no-return cells (NaN
//! position and range) for the caller to count (`classifier::ordering` skips them, decision 0,
//! and refuses a file where they are more than a handful).
//!
//! # Scan order
//! Real KITTI `.bin` files store a frame laser by laser, from the top laser down, and each laser's
//! points as one counter-clockwise turn of azimuth that starts near the front (azimuth 0), passes
//! the back (where the azimuth wraps from +pi to -pi) and ends just right of the front. The writer
//! does the same ([`scan_order`]): per echo plane, rows from the top one (highest elevation) down,
//! and in each row the columns from `cols / 2` (the column at or just left of the front for a
//! full-turn sensor, whose column 0 is at +pi) down to 0 and then from `cols - 1` down to
//! `cols / 2 + 1`; cells without a return are skipped. Scan unfolding
//! (`classifier::ordering`) recovers rows and columns from that order.
//!
//! # Firing order
//! The ROS drivers of Hesai and RoboSense sensors (nebula) emit a cloud in **firing order**: the
//! lasers of one firing cycle, in the order of the sensor's channel table, then the next cycle; in
//! dual-return mode both echoes of a cycle before the next one. [`firing_order`] gives that order
//! (from each cell's firing time), and [`encode_in_order`] writes a `.bin` in it: a ring-less file
//! as a user converting such a cloud gets.

use std::path::Path;

use glam::{Affine3A, Vec3};

use super::read_util::read_file;
use crate::cloud::OrderedCloud;
use crate::error::{Result, SimError};
use crate::scene::SemanticClass;

/// Encodes the returns of `cloud` as KITTI `.bin` and `.label` bytes, transforming points by
/// `sensor_from_vehicle` when given. Returns `(bin, label, points)`.
pub fn encode(cloud: &OrderedCloud, sensor_from_vehicle: Option<&Affine3A>) -> Result<(Vec<u8>, Vec<u8>, usize)> {
    cloud.check_consistent().map_err(|m| SimError::invalid("cloud", m, "every field planes*rows*cols long"))?;
    encode_in_order(cloud, &scan_order(cloud), sensor_from_vehicle)
}

/// As [`encode`], with the returns in `order` (cells of `cloud`, e.g. [`firing_order`]'s) rather
/// than scan order. Refused for a cell beyond the cloud.
pub fn encode_in_order(
    cloud: &OrderedCloud,
    order: &[usize],
    sensor_from_vehicle: Option<&Affine3A>,
) -> Result<(Vec<u8>, Vec<u8>, usize)> {
    cloud.check_consistent().map_err(|m| SimError::invalid("cloud", m, "every field planes*rows*cols long"))?;
    if let Some(&bad) = order.iter().find(|&&i| i >= cloud.len()) {
        return Err(SimError::invalid("order", bad, format!("cells 0 ..= {} of the cloud", cloud.len().max(1) - 1)));
    }
    let n = order.len();
    let mut bin = Vec::with_capacity(n * 16);
    let mut label = Vec::with_capacity(n * 4);
    for &i in order {
        let p = cloud.point_in_vehicle[i];
        let p = sensor_from_vehicle.map_or(p, |t| t.transform_point3(p));
        let mut rec = [0u8; 16];
        rec[0..4].copy_from_slice(&p.x.to_le_bytes());
        rec[4..8].copy_from_slice(&p.y.to_le_bytes());
        rec[8..12].copy_from_slice(&p.z.to_le_bytes());
        rec[12..16].copy_from_slice(&cloud.intensity[i].clamp(0.0, 1.0).to_le_bytes());
        bin.extend_from_slice(&rec);
        let l = u32::from(cloud.label[i].semantic_kitti_id()) | ((cloud.instance[i] & 0xFFFF) << 16);
        label.extend_from_slice(&l.to_le_bytes());
    }
    Ok((bin, label, n))
}

/// The cells of `cloud` that hold a return, in the order the `.bin` stores them (module docs,
/// "Scan order"): the `k`-th point of the file is cell `scan_order(cloud)[k]`.
pub fn scan_order(cloud: &OrderedCloud) -> Vec<usize> {
    let (rows, cols) = (cloud.rows, cloud.cols);
    let front = cols / 2;
    let mut order = Vec::with_capacity(cloud.returns());
    for plane in 0..cloud.planes {
        for row in (0..rows).rev() {
            // Counter-clockwise = azimuth increasing = column index decreasing, wrapping.
            for k in 0..cols {
                let col = (front + cols - k) % cols;
                let i = cloud.index(plane, row, col);
                if cloud.has_return(i) {
                    order.push(i);
                }
            }
        }
    }
    order
}

/// The cells of `cloud` that hold a return in firing order (module docs, "Firing order"): by firing
/// cycle (`floor(time_s / cycle_s)`, `cycle_s` the sensor's firing cycle), then echo plane, then
/// `firing_rank_of_row[row]` (the row's channel index in the sensor's table). Rows beyond
/// `firing_rank_of_row` go after the others, in row order.
pub fn firing_order(cloud: &OrderedCloud, firing_rank_of_row: &[usize], cycle_s: f64) -> Vec<usize> {
    let plane_cells = cloud.rows * cloud.cols;
    let mut keyed: Vec<(i64, usize, usize, usize)> = (0..cloud.len())
        .filter(|&i| cloud.has_return(i))
        .map(|i| {
            let (plane, row) = (i / plane_cells.max(1), (i % plane_cells.max(1)) / cloud.cols.max(1));
            let cycle = if cycle_s > 0.0 { (cloud.time_s[i] / cycle_s).floor() as i64 } else { 0 };
            let rank = firing_rank_of_row.get(row).copied().unwrap_or(firing_rank_of_row.len() + row);
            (cycle, plane, rank, i)
        })
        .collect();
    keyed.sort_unstable();
    keyed.into_iter().map(|k| k.3).collect()
}

/// The calibration text: `Tr:` followed by the 12 row-major entries of `vehicle_from_sensor`.
pub fn calib_text(vehicle_from_sensor: &Affine3A) -> String {
    let m = vehicle_from_sensor.matrix3;
    let t = vehicle_from_sensor.translation;
    let rows = [
        [m.x_axis.x, m.y_axis.x, m.z_axis.x, t.x],
        [m.x_axis.y, m.y_axis.y, m.z_axis.y, t.y],
        [m.x_axis.z, m.y_axis.z, m.z_axis.z, t.z],
    ];
    let vals: Vec<String> = rows.iter().flatten().map(|v| format!("{v:e}")).collect();
    format!("Tr: {}\n", vals.join(" "))
}

/// Parses a calibration text's `Tr:` line into `vehicle_from_sensor`.
pub fn parse_calib(path: &Path, text: &str) -> Result<Affine3A> {
    let line = text
        .lines()
        .find_map(|l| l.trim().strip_prefix("Tr:"))
        .ok_or_else(|| SimError::bad_file(path, "calibration has no `Tr:` line"))?;
    let v: Vec<f32> = line
        .split_whitespace()
        .map(|s| s.parse::<f32>().map_err(|_| SimError::bad_file(path, format!("calibration: `{s}` is not a number"))))
        .collect::<Result<_>>()?;
    if v.len() != 12 || v.iter().any(|x| !x.is_finite()) {
        return Err(SimError::bad_file(path, format!("calibration `Tr:` needs 12 finite numbers, has {}", v.len())));
    }
    Ok(Affine3A::from_cols_array(&[v[0], v[4], v[8], v[1], v[5], v[9], v[2], v[6], v[10], v[3], v[7], v[11]]))
}

/// Reads `bin` (and `label` if given) into a `1 x N` cloud.
pub fn read(bin: &Path, label: Option<&Path>) -> Result<OrderedCloud> {
    let b = read_file(bin)?;
    let l = label.map(read_file).transpose()?;
    read_bytes(bin, &b, label.zip(l.as_deref()))
}

/// The records of a KITTI `.bin` (and its `.label`) in file order, without the cloud around them:
/// what ordering needs from a file of another tool ([`read_bytes`] builds a whole `1 x N` cloud).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct KittiPoints {
    /// Point per record, sensor frame, metres (as stored: NaN or infinite coordinates kept).
    pub points: Vec<Vec3>,
    /// Intensity per record.
    pub intensity: Vec<f32>,
    /// Semantic class per record (the label's low 16 bits), when a `.label` was read.
    pub labels: Option<Vec<SemanticClass>>,
}

/// Reads `bin` (and `label` if given) as [`KittiPoints`]; refused as [`read_bytes`] refuses.
pub fn read_points(bin: &Path, label: Option<&Path>) -> Result<KittiPoints> {
    let b = read_file(bin)?;
    let l = label.map(read_file).transpose()?;
    points_from_bytes(bin, &b, label.zip(l.as_deref()))
}

/// Parses KITTI `.bin` bytes into [`KittiPoints`] (lengths checked as in [`read_bytes`]).
pub fn points_from_bytes(bin_path: &Path, bin: &[u8], label: Option<(&Path, &[u8])>) -> Result<KittiPoints> {
    let mut out = KittiPoints::default();
    points_from_bytes_into(bin_path, bin, label, &mut out)?;
    Ok(out)
}

/// As [`points_from_bytes`], into `out`, whose buffers are reused (frames read one after another
/// allocate nothing once they are large enough).
pub fn points_from_bytes_into(
    bin_path: &Path,
    bin: &[u8],
    label: Option<(&Path, &[u8])>,
    out: &mut KittiPoints,
) -> Result<()> {
    let n = check_lengths(bin_path, bin, label)?;
    out.points.clear();
    out.intensity.clear();
    out.points.reserve(n);
    out.intensity.reserve(n);
    decode_records(bin, &mut out.points, &mut out.intensity);
    decode_labels(label, out);
    Ok(())
}

/// The records of KITTI `.bin` bytes where they lie, for a reader that takes them so (ordering:
/// `classifier::ordering::InputPoint`): `Some(records)`, `x y z intensity` per point as a view of
/// `bin` (no copy), where `bin` is 4-byte aligned on a little-endian machine; otherwise `None`,
/// with the points and intensities decoded into `out` as [`points_from_bytes_into`] decodes them.
/// The `.label`'s classes go to `out.labels` either way; lengths are checked as in [`read_bytes`].
///
/// ```
/// # use std::path::Path;
/// let mut bin = Vec::new();
/// for v in [1.0f32, 2.0, 3.0, 0.5, -1.0, 0.0, 4.0, 0.25] {
///     bin.extend_from_slice(&v.to_le_bytes());
/// }
/// let mut out = sim::io::kitti::KittiPoints::default();
/// match sim::io::kitti::records_or_points_into(Path::new("f.bin"), &bin, None, &mut out).unwrap() {
///     Some(records) => assert_eq!(records, &[[1.0, 2.0, 3.0, 0.5], [-1.0, 0.0, 4.0, 0.25]]),
///     None => assert_eq!(out.intensity, [0.5, 0.25]),
/// }
/// ```
pub fn records_or_points_into<'a>(
    bin_path: &Path,
    bin: &'a [u8],
    label: Option<(&Path, &[u8])>,
    out: &mut KittiPoints,
) -> Result<Option<&'a [[f32; 4]]>> {
    check_lengths(bin_path, bin, label)?;
    let in_place =
        if cfg!(target_endian = "little") { bytemuck::try_cast_slice::<u8, [f32; 4]>(bin).ok() } else { None };
    let Some(records) = in_place else {
        points_from_bytes_into(bin_path, bin, label, out)?;
        return Ok(None);
    };
    out.points.clear();
    out.intensity.clear();
    decode_labels(label, out);
    Ok(Some(records))
}

/// Decodes the `.label`'s classes (low 16 bits) into `out.labels`, or sets it to `None`.
fn decode_labels(label: Option<(&Path, &[u8])>, out: &mut KittiPoints) {
    match label {
        Some((_, lb)) => {
            let labels = out.labels.get_or_insert_with(Vec::new);
            labels.clear();
            labels.extend(
                lb.chunks_exact(4)
                    .map(|c| SemanticClass((u32::from_le_bytes([c[0], c[1], c[2], c[3]]) & 0xFFFF) as u16)),
            );
        }
        None => out.labels = None,
    }
}

/// Appends the points and intensities of the 16-byte records of `bin` (compiled for AVX2 where
/// the CPU has it: the records are unpacked 8 at a time, about 0.1 ms less per 124 k-point frame).
fn decode_records(bin: &[u8], points: &mut Vec<Vec3>, intensity: &mut Vec<f32>) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU supports AVX2 (checked just above).
        #[allow(unsafe_code)]
        unsafe {
            return decode_records_avx2(bin, points, intensity);
        }
    }
    decode_records_body(bin, points, intensity);
}

/// [`decode_records_body`] compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn decode_records_avx2(bin: &[u8], points: &mut Vec<Vec3>, intensity: &mut Vec<f32>) {
    decode_records_body(bin, points, intensity);
}

/// The body of [`decode_records`]: two extends of exact length (no capacity test per record).
#[inline(always)]
fn decode_records_body(bin: &[u8], points: &mut Vec<Vec3>, intensity: &mut Vec<f32>) {
    let f = |b: &[u8], k: usize| f32::from_le_bytes([b[k], b[k + 1], b[k + 2], b[k + 3]]);
    points.extend(bin.chunks_exact(16).map(|rec| Vec3::new(f(rec, 0), f(rec, 4), f(rec, 8))));
    intensity.extend(bin.chunks_exact(16).map(|rec| f(rec, 12)));
}

/// Checks that `bin` holds whole 16-byte records and `label` one uint32 per record; the record count.
fn check_lengths(bin_path: &Path, bin: &[u8], label: Option<(&Path, &[u8])>) -> Result<usize> {
    if !bin.len().is_multiple_of(16) {
        return Err(SimError::bad_file(
            bin_path,
            format!("KITTI .bin length {} is not a multiple of 16 bytes (float32 x y z intensity)", bin.len()),
        ));
    }
    let n = bin.len() / 16;
    if let Some((lp, lb)) = label
        && lb.len() != n * 4
    {
        return Err(SimError::bad_file(
            lp,
            format!(
                ".label holds {} bytes ({} labels{}) but {} has {n} points",
                lb.len(),
                lb.len() / 4,
                if !lb.len().is_multiple_of(4) { " and a partial one" } else { "" },
                bin_path.display()
            ),
        ));
    }
    Ok(n)
}

/// Parses KITTI `.bin` bytes (from `bin_path`) and optional `(label_path, label_bytes)`.
pub fn read_bytes(bin_path: &Path, bin: &[u8], label: Option<(&Path, &[u8])>) -> Result<OrderedCloud> {
    let n = check_lengths(bin_path, bin, label)?;
    let mut cloud = OrderedCloud::empty(1, n, 1);
    let f = |b: &[u8], k: usize| f32::from_le_bytes([b[k], b[k + 1], b[k + 2], b[k + 3]]);
    for (i, rec) in bin.chunks_exact(16).enumerate() {
        let p = Vec3::new(f(rec, 0), f(rec, 4), f(rec, 8));
        let hit = p.is_finite();
        cloud.point_in_vehicle[i] = if hit { p } else { Vec3::NAN };
        cloud.range_m[i] = if hit { p.length() } else { f32::NAN };
        cloud.intensity[i] = f(rec, 12);
        cloud.column[i] = i as u32;
        cloud.sensor[i] = 0;
        if let Some((_, lb)) = label {
            let l = u32::from_le_bytes([lb[4 * i], lb[4 * i + 1], lb[4 * i + 2], lb[4 * i + 3]]);
            let class = SemanticClass((l & 0xFFFF) as u16);
            cloud.label[i] = class;
            cloud.instance[i] = l >> 16;
            cloud.ground[i] = hit && class.is_ground();
        }
    }
    Ok(cloud)
}
