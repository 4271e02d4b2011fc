//! nuScenes LiDAR files and their lidarseg labels.
//!
//! A nuScenes `LIDAR_TOP` sweep (`samples/LIDAR_TOP/<name>.pcd.bin`, an HDL-32E) is a headerless
//! run of 20-byte records, five little-endian float32 per point: `x y z intensity ring`, the ring
//! (laser) a whole number, 0 ..= 31 for the HDL-32E (ring 0 at the bottom). A lidarseg label file
//! (`lidarseg/<version>/<token>_lidarseg.bin`) holds one uint8 class id per point of its sweep.
//!
//! A KITTI `.bin` ([`super::kitti`]) is a run of 16-byte records: a file of a length divisible by
//! both 16 and 20 fits both layouts. [`layout_of_bytes`] says which one the bytes give away: the
//! fifth float32 of every 20-byte record is a whole number within `0 ..= MAX_RING`, one of them at
//! least is not 0, and the file is not all whole numbers (a real sweep's coordinates are not).
//! Read as KITTI records, those whole numbers would fall on `x`, `y`, `z` and intensity in turn:
//! in a real KITTI file the first of its coordinates that is not a whole number in `0 ..= 127`
//! (the first or second point, in practice) rules the nuScenes reading out.
//!
//! The reader never panics on malformed input: a length that is not a whole number of records, a
//! ring that is not a whole number within range, a label file of another length or with an id
//! beyond the taxonomy are [`crate::SimError::BadFile`] naming the file, the point and the field.

use std::path::Path;

use glam::Vec3;

use super::read_util::read_file;
use crate::cloud::OrderedCloud;
use crate::error::{Result, SimError};
use crate::scene::SemanticClass;

/// Bytes per nuScenes point: five float32, `x y z intensity ring`.
pub const RECORD_BYTES: usize = 20;

/// Bytes per KITTI point: four float32, `x y z intensity`.
pub const KITTI_RECORD_BYTES: usize = 16;

/// Largest ring a nuScenes-layout file may hold (the widest spinning sensors have 128 lasers).
pub const MAX_RING: u16 = 127;

/// The largest lidarseg class id (nuScenes-lidarseg has 32 classes, 0 ..= 31).
pub const MAX_LIDARSEG_CLASS: u8 = 31;

/// The raw layouts a headerless `.bin` file may have.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RawLayout {
    /// KITTI: `x y z intensity`, 16 bytes per point.
    Kitti,
    /// nuScenes: `x y z intensity ring`, 20 bytes per point.
    Nuscenes,
}

/// The points of a nuScenes file in file order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct NuscenesPoints {
    /// Point per record, sensor frame, metres (as stored: NaN or infinite coordinates kept).
    pub points: Vec<Vec3>,
    /// Intensity per record (as stored, 0 ..= 255 in nuScenes).
    pub intensity: Vec<f32>,
    /// Ring (laser) per record.
    pub rings: Vec<u16>,
}

/// The little-endian float32 at byte `at` of `bytes` (which holds 4 bytes there).
fn f32_at(bytes: &[u8], at: usize) -> f32 {
    f32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]])
}

/// Whether `v` is a ring value: a whole number within `0 ..= MAX_RING`.
fn is_ring(v: f32) -> bool {
    (0.0..=f32::from(MAX_RING)).contains(&v) && v.fract() == 0.0
}

/// Whether the bytes, read as 20-byte records, give away the nuScenes layout (module docs): every
/// fifth value is a ring, one ring at least is not 0, and one value of the file at least is not a
/// whole number. `bytes.len()` is a multiple of [`RECORD_BYTES`].
fn rings_give_away(bytes: &[u8]) -> bool {
    let mut nonzero_ring = false;
    for rec in bytes.chunks_exact(RECORD_BYTES) {
        let ring = f32_at(rec, 16);
        if !is_ring(ring) {
            return false;
        }
        nonzero_ring |= ring != 0.0;
    }
    let fractional = bytes.chunks_exact(4).any(|w| f32_at(w, 0).fract() != 0.0);
    nonzero_ring && fractional
}

/// The layout a headerless `.bin` file's bytes give away, and whether they decide it (`true`) or
/// the length alone fits one layout only (`false`): only nuScenes' 20-byte records fit (then the
/// rings are checked as the file is read), only KITTI's 16-byte records fit, or both fit and the
/// fifth value of every 20-byte record gives the nuScenes layout away (module docs), else KITTI.
/// Refused, naming `path`: a length that fits neither.
///
/// ```
/// use sim::io::nuscenes::{RawLayout, layout_of_bytes};
/// let mut nu = Vec::new();
/// for ring in 0..4u8 {
///     for v in [1.5f32, -2.25, 0.125, 7.0, f32::from(ring)] {
///         nu.extend_from_slice(&v.to_le_bytes());
///     }
/// }
/// // 80 bytes: four nuScenes points or five KITTI points; the rings give it away.
/// assert_eq!(layout_of_bytes("f.bin".as_ref(), &nu)?, RawLayout::Nuscenes);
/// assert_eq!(layout_of_bytes("f.bin".as_ref(), &nu[..64])?, RawLayout::Kitti);
/// assert!(layout_of_bytes("f.bin".as_ref(), &nu[..70]).is_err());
/// # Ok::<(), sim::SimError>(())
/// ```
pub fn layout_of_bytes(path: &Path, bytes: &[u8]) -> Result<RawLayout> {
    Ok(content_layout(path, bytes)?.0)
}

/// As [`layout_of_bytes`], also saying whether the content decided it (`true`: the length fits
/// both layouts and the rings gave nuScenes away) or the length alone did (`false`).
pub fn content_layout(path: &Path, bytes: &[u8]) -> Result<(RawLayout, bool)> {
    let (kitti, nuscenes) = (bytes.len().is_multiple_of(KITTI_RECORD_BYTES), bytes.len().is_multiple_of(RECORD_BYTES));
    match (kitti, nuscenes) {
        (false, false) => Err(SimError::bad_file(
            path,
            format!(
                "{} bytes fit neither layout: a KITTI .bin holds {KITTI_RECORD_BYTES} bytes per point (x y z \
                 intensity), a nuScenes .pcd.bin {RECORD_BYTES} (x y z intensity ring)",
                bytes.len()
            ),
        )),
        (true, false) => Ok((RawLayout::Kitti, false)),
        (false, true) => Ok((RawLayout::Nuscenes, false)),
        (true, true) if rings_give_away(bytes) => Ok((RawLayout::Nuscenes, true)),
        (true, true) => Ok((RawLayout::Kitti, false)),
    }
}

/// Parses nuScenes bytes into `out` (buffers reused). Refused, naming `path`: a length that is not
/// a whole number of 20-byte records (a 16-byte-record file says so), a ring that is not a whole
/// number within `0 ..= MAX_RING` (the first such point named).
pub fn points_from_bytes_into(path: &Path, bytes: &[u8], out: &mut NuscenesPoints) -> Result<()> {
    if !bytes.len().is_multiple_of(RECORD_BYTES) {
        let kitti = if bytes.len().is_multiple_of(KITTI_RECORD_BYTES) {
            " (it fits 16-byte KITTI records: x y z intensity, no ring)"
        } else {
            ""
        };
        return Err(SimError::bad_file(
            path,
            format!(
                "nuScenes layout: {} bytes is not a whole number of {RECORD_BYTES}-byte x y z intensity ring \
                 records{kitti}",
                bytes.len()
            ),
        ));
    }
    let n = bytes.len() / RECORD_BYTES;
    out.points.clear();
    out.intensity.clear();
    out.rings.clear();
    out.points.reserve(n);
    out.intensity.reserve(n);
    out.rings.reserve(n);
    for (k, rec) in bytes.chunks_exact(RECORD_BYTES).enumerate() {
        let ring = f32_at(rec, 16);
        if !is_ring(ring) {
            return Err(SimError::bad_file(
                path,
                format!(
                    "nuScenes layout: point {k} has ring {ring} (the fifth float32): allowed a whole number \
                     within 0 ..= {MAX_RING}"
                ),
            ));
        }
        out.points.push(Vec3::new(f32_at(rec, 0), f32_at(rec, 4), f32_at(rec, 8)));
        out.intensity.push(f32_at(rec, 12));
        out.rings.push(ring as u16);
    }
    Ok(())
}

/// Reads a nuScenes file as [`NuscenesPoints`] (refused as [`points_from_bytes_into`] refuses).
pub fn read_points(path: &Path) -> Result<NuscenesPoints> {
    let bytes = read_file(path)?;
    let mut out = NuscenesPoints::default();
    points_from_bytes_into(path, &bytes, &mut out)?;
    Ok(out)
}

/// Reads a nuScenes file into a `1 x N` cloud in file order (`ring` from the file, `column` = point
/// index, `range_m` from the origin; NaN or infinite points kept as no-return cells, as
/// [`super::kitti::read`] keeps them).
pub fn read(path: &Path) -> Result<OrderedCloud> {
    cloud_from_bytes(path, &read_file(path)?)
}

/// As [`read`], from the file's bytes.
pub fn cloud_from_bytes(path: &Path, bytes: &[u8]) -> Result<OrderedCloud> {
    let mut p = NuscenesPoints::default();
    points_from_bytes_into(path, bytes, &mut p)?;
    let mut cloud = OrderedCloud::empty(1, p.points.len(), 1);
    for (i, &q) in p.points.iter().enumerate() {
        let hit = q.is_finite();
        cloud.point_in_vehicle[i] = if hit { q } else { Vec3::NAN };
        cloud.range_m[i] = if hit { q.length() } else { f32::NAN };
        cloud.intensity[i] = p.intensity[i];
        cloud.ring[i] = p.rings[i];
        cloud.column[i] = i as u32;
        cloud.sensor[i] = 0;
    }
    Ok(cloud)
}

/// The bytes of nuScenes records `x y z intensity ring` (the layout a `.pcd.bin` holds).
pub fn encode(records: &[[f32; 5]]) -> Vec<u8> {
    records.iter().flatten().flat_map(|v| v.to_le_bytes()).collect()
}

/// The SemanticKITTI class of a nuScenes-lidarseg class id, so that the protocols
/// (`classifier::dataset::protocol`) score nuScenes labels as they score SemanticKITTI's: ground
/// 24 `flat.driveable_surface` -> 40 road, 25 `flat.other` -> 49 other-ground, 26 `flat.sidewalk`
/// -> 48 sidewalk, 27 `flat.terrain` -> 72 terrain; left out 0 `noise` -> 1 outlier, 31
/// `vehicle.ego` -> 0 unlabeled; 30 `static.vegetation` -> 70 vegetation; every other class to a
/// non-ground class (people 30, vehicles 10 ..= 20, movable objects and static others 99, barriers
/// 51 fence, man-made 50 building). `None` for an id beyond [`MAX_LIDARSEG_CLASS`].
pub fn lidarseg_to_semantic_kitti(id: u8) -> Option<SemanticClass> {
    let sk = match id {
        0 => 1,
        1 => 99,       // animal
        2..=8 => 30,   // human.pedestrian.*
        9 => 51,       // movable_object.barrier
        10..=13 => 99, // movable_object.{debris, pushable_pullable, trafficcone}, static_object.bicycle_rack
        14 => 11,      // vehicle.bicycle
        15 | 16 => 13, // vehicle.bus.*
        17 => 10,      // vehicle.car
        18 => 18,      // vehicle.construction
        19 | 20 => 20, // vehicle.emergency.*
        21 => 15,      // vehicle.motorcycle
        22 => 20,      // vehicle.trailer
        23 => 18,      // vehicle.truck
        24 => 40,      // flat.driveable_surface
        25 => 49,      // flat.other
        26 => 48,      // flat.sidewalk
        27 => 72,      // flat.terrain
        28 => 50,      // static.manmade
        29 => 99,      // static.other
        30 => 70,      // static.vegetation
        31 => 0,       // vehicle.ego
        _ => return None,
    };
    Some(SemanticClass(sk))
}

/// Reads a lidarseg label file of `points` points as SemanticKITTI classes
/// ([`lidarseg_to_semantic_kitti`]). Refused, naming `path`: another length than one byte per
/// point (`cloud` named), a class id beyond [`MAX_LIDARSEG_CLASS`].
pub fn read_lidarseg(path: &Path, cloud: &Path, points: usize) -> Result<Vec<SemanticClass>> {
    let bytes = read_file(path)?;
    lidarseg_from_bytes(path, &bytes, cloud, points)
}

/// As [`read_lidarseg`], from the file's bytes.
pub fn lidarseg_from_bytes(path: &Path, bytes: &[u8], cloud: &Path, points: usize) -> Result<Vec<SemanticClass>> {
    if bytes.len() != points {
        return Err(SimError::bad_file(
            path,
            format!(
                "lidarseg labels: {} bytes (one uint8 per point) but `{}` has {points} points",
                bytes.len(),
                cloud.display()
            ),
        ));
    }
    bytes
        .iter()
        .enumerate()
        .map(|(k, &id)| {
            lidarseg_to_semantic_kitti(id).ok_or_else(|| {
                SimError::bad_file(
                    path,
                    format!("lidarseg labels: point {k} has class {id}: allowed 0 ..= {MAX_LIDARSEG_CLASS}"),
                )
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `n` points of a 32-ring sweep with fractional coordinates and intensities.
    fn sweep(n: usize) -> Vec<[f32; 5]> {
        (0..n)
            .map(|k| {
                let a = k as f32 * 0.0173;
                [
                    10.0 * a.cos() + 0.013,
                    10.0 * a.sin() - 0.021,
                    -1.7 + 0.001 * k as f32,
                    (k % 97) as f32,
                    (k % 32) as f32,
                ]
            })
            .collect()
    }

    /// KITTI records of a real-looking frame (fractional metres, intensity in 0 ..= 1).
    fn kitti(n: usize) -> Vec<u8> {
        (0..n)
            .flat_map(|k| {
                let a = k as f32 * 0.011;
                [20.0 * a.cos() + 0.37, 20.0 * a.sin() + 0.11, -1.73, 0.25]
            })
            .flat_map(f32::to_le_bytes)
            .collect()
    }

    fn p() -> &'static Path {
        Path::new("frame.bin")
    }

    #[test]
    fn the_length_alone_decides_where_one_layout_fits() {
        // 3 nuScenes points = 60 bytes (not a multiple of 16); 5 KITTI points = 80 (of both);
        // 4 KITTI points = 64 (of 16 only).
        assert_eq!(content_layout(p(), &encode(&sweep(3))).unwrap(), (RawLayout::Nuscenes, false));
        assert_eq!(content_layout(p(), &kitti(4)).unwrap(), (RawLayout::Kitti, false));
        assert_eq!(content_layout(p(), &kitti(5)).unwrap(), (RawLayout::Kitti, false));
        let e = content_layout(p(), &[0u8; 42]).unwrap_err().to_string();
        assert!(e.contains("frame.bin") && e.contains("42 bytes fit neither layout"), "{e}");
    }

    #[test]
    fn rings_give_nuscenes_away_where_both_layouts_fit() {
        // 4 points (80 bytes), 32 and 34,720 (a real sweep's count: 694,400 bytes, a multiple of 80).
        for n in [4, 32, 34_720] {
            let bytes = encode(&sweep(n));
            assert!(bytes.len().is_multiple_of(16));
            assert_eq!(content_layout(p(), &bytes).unwrap(), (RawLayout::Nuscenes, true), "{n} points");
        }
        // Real KITTI records of the same lengths are KITTI.
        for n in [5, 40, 43_400] {
            assert_eq!(content_layout(p(), &kitti(n)).unwrap(), (RawLayout::Kitti, false), "{n} KITTI points");
        }
    }

    #[test]
    fn edge_cases_stay_kitti() {
        // An empty file, a file of zeros (every ring 0), a file of whole numbers only (a synthetic
        // grid: no measurement gives it away) are read as the name says.
        assert_eq!(content_layout(p(), &[]).unwrap(), (RawLayout::Kitti, false));
        assert_eq!(content_layout(p(), &[0u8; 160]).unwrap(), (RawLayout::Kitti, false));
        let whole: Vec<[f32; 5]> = (0..8).map(|k| [1.0, 2.0, 3.0, 4.0, (k % 3) as f32]).collect();
        assert_eq!(content_layout(p(), &encode(&whole)).unwrap(), (RawLayout::Kitti, false));
        // One ring beyond range, fractional, negative or NaN: not nuScenes by content.
        for bad in [128.0f32, 3.5, -1.0, f32::NAN, f32::INFINITY] {
            let mut s = sweep(8);
            s[5][4] = bad;
            assert_eq!(content_layout(p(), &encode(&s)).unwrap().0, RawLayout::Kitti, "ring {bad}");
        }
        // The largest ring is taken.
        let mut s = sweep(8);
        s[3][4] = 127.0;
        assert_eq!(content_layout(p(), &encode(&s)).unwrap().0, RawLayout::Nuscenes);
    }

    #[test]
    fn points_are_read_with_their_rings_and_bad_rings_are_refused() {
        let s = sweep(6);
        let mut out = NuscenesPoints::default();
        points_from_bytes_into(p(), &encode(&s), &mut out).unwrap();
        assert_eq!(out.rings, [0, 1, 2, 3, 4, 5]);
        assert_eq!(out.points[2], Vec3::new(s[2][0], s[2][1], s[2][2]));
        assert_eq!(out.intensity[5], 5.0);
        let mut bad = s.clone();
        bad[4][4] = 2.5;
        let e = points_from_bytes_into(p(), &encode(&bad), &mut out).unwrap_err().to_string();
        assert!(e.contains("frame.bin") && e.contains("point 4 has ring 2.5") && e.contains("0 ..= 127"), "{e}");
        bad[4][4] = 200.0;
        let e = points_from_bytes_into(p(), &encode(&bad), &mut out).unwrap_err().to_string();
        assert!(e.contains("ring 200"), "{e}");
        // A 4-float file: refused, saying it fits KITTI records.
        let e = points_from_bytes_into(p(), &kitti(4), &mut out).unwrap_err().to_string();
        assert!(e.contains("64 bytes") && e.contains("16-byte KITTI"), "{e}");
    }

    #[test]
    fn lidarseg_labels_map_to_semantic_kitti_and_are_checked() {
        let got = lidarseg_from_bytes(p(), &[24, 25, 26, 27, 0, 31, 17, 30], p(), 8).unwrap();
        let ids: Vec<u16> = got.iter().map(|c| c.0).collect();
        assert_eq!(ids, [40, 49, 48, 72, 1, 0, 10, 70]);
        let e = lidarseg_from_bytes(p(), &[1, 2], p(), 3).unwrap_err().to_string();
        assert!(e.contains("2 bytes") && e.contains("3 points"), "{e}");
        let e = lidarseg_from_bytes(p(), &[1, 32], p(), 2).unwrap_err().to_string();
        assert!(e.contains("point 1 has class 32") && e.contains("0 ..= 31"), "{e}");
        assert!((0..=31).all(|id| lidarseg_to_semantic_kitti(id).is_some()));
    }

    proptest::proptest! {
        /// Any bytes: the layout test and the readers answer, never panic; where the content gives
        /// nuScenes away, the reader takes the file, with a ring per point.
        #[test]
        fn any_bytes_are_answered_and_content_nuscenes_reads(bytes in proptest::collection::vec(proptest::prelude::any::<u8>(), 0..400)) {
            let layout = content_layout(p(), &bytes);
            let mut out = NuscenesPoints::default();
            let read = points_from_bytes_into(p(), &bytes, &mut out);
            if let Ok((RawLayout::Nuscenes, true)) = layout {
                proptest::prop_assert!(read.is_ok());
                proptest::prop_assert_eq!(out.rings.len(), bytes.len() / RECORD_BYTES);
            }
            let _ = lidarseg_from_bytes(p(), &bytes, p(), bytes.len());
        }
    }
}
