//! Azimuth, horizontal distance and `tan(elevation)` of every usable point of a cloud in one pass
//! that the compiler vectorizes: the first step of scan unfolding, where a per-point scalar loop
//! cost about 1 ms of a 124 k-point KITTI frame. The azimuth is [`fast_atan2`]'s, bit for bit:
//! the same operations in the same order, its branches written as selects. Over every point of a
//! cloud the same pass counts the bad points and no-returns ([`super::usable`]), so that the
//! points are read once where all of them are usable (the common case).

use super::input_point::InputPoint;
use super::usable::bad_and_no_return;

#[cfg(test)]
use super::beam_table::fast_atan2;

/// Points gathered and computed together.
const LANES: usize = 16;

/// The azimuth (rad), horizontal distance (m) and `tan(elevation)` of points, one per point.
pub(crate) type Polar = (Vec<f32>, Vec<f32>, Vec<f32>);

/// `(azimuth_rad, horizontal_distance_m, tan_elevation)` of `points[k]` for every `k` in `valid`
/// (every point where `valid` is `None`), in that order; `tan_elevation` is seen from the sensor
/// origin (`z / max(d, 1e-6)`).
pub(crate) fn polar<P: InputPoint>(points: &[P], valid: Option<&[u32]>) -> Polar {
    polar_counting(points, valid).0
}

/// [`polar`] and the counts of the points read that have a non-finite coordinate and of those at
/// (0, 0, 0), as [`super::usable`] counts them.
pub(crate) fn polar_counting<P: InputPoint>(points: &[P], valid: Option<&[u32]>) -> (Polar, (usize, usize)) {
    #[cfg(target_arch = "x86_64")]
    if crate::cpu::avx512() {
        // SAFETY: the CPU supports AVX-512 F, BW, VL and DQ, AVX2, BMI1 and BMI2 (checked just above).
        #[allow(unsafe_code)]
        unsafe {
            return polar_avx512(points, valid);
        }
    }
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU supports AVX2 (checked just above).
        #[allow(unsafe_code)]
        unsafe {
            return polar_avx2(points, valid);
        }
    }
    polar_body(points, valid)
}

/// [`polar_body`] compiled for AVX2 (plain IEEE operations only: the same bits as without it).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn polar_avx2<P: InputPoint>(points: &[P], valid: Option<&[u32]>) -> (Polar, (usize, usize)) {
    polar_body(points, valid)
}

/// [`polar_body`] compiled for AVX-512 ([`crate::cpu::avx512`]) (plain IEEE operations only: the same bits as without it).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512bw,avx512vl,avx512dq,avx2,bmi1,bmi2")]
fn polar_avx512<P: InputPoint>(points: &[P], valid: Option<&[u32]>) -> (Polar, (usize, usize)) {
    polar_body(points, valid)
}

#[inline(always)]
fn polar_body<P: InputPoint>(points: &[P], valid: Option<&[u32]>) -> (Polar, (usize, usize)) {
    let m = valid.map_or(points.len(), <[u32]>::len);
    // Filled lane block by lane block (not zeroed first: that `memset` cost 0.1 ms a KITTI frame).
    let (mut az, mut dist, mut fine) = (Vec::with_capacity(m), Vec::with_capacity(m), Vec::with_capacity(m));
    // Per lane: points with a non-finite coordinate, points at (0, 0, 0).
    let (mut bad, mut zero) = ([0u32; LANES], [0u32; LANES]);
    for j in 0..m.div_ceil(LANES) {
        // Lanes past the last point hold (1, 1, 1): counted as neither.
        let (mut x, mut y, mut z) = ([1f32; LANES], [1f32; LANES], [1f32; LANES]);
        let n = LANES.min(m - j * LANES);
        match valid {
            Some(valid) => {
                for (l, &k) in valid[j * LANES..j * LANES + n].iter().enumerate() {
                    let p = points[k as usize].xyz();
                    (x[l], y[l], z[l]) = (p.x, p.y, p.z);
                }
            }
            None => {
                let block = &points[j * LANES..j * LANES + n];
                // A whole block as an array: a loop of known length, which the compiler unrolls
                // into vector loads and shuffles.
                if let Ok(whole) = <&[P; LANES]>::try_from(block) {
                    for l in 0..LANES {
                        let p = whole[l].xyz();
                        (x[l], y[l], z[l]) = (p.x, p.y, p.z);
                    }
                } else {
                    for (l, p) in block.iter().enumerate() {
                        let p = p.xyz();
                        (x[l], y[l], z[l]) = (p.x, p.y, p.z);
                    }
                }
            }
        }
        let (mut oa, mut od, mut of) = ([0f32; LANES], [0f32; LANES], [0f32; LANES]);
        for l in 0..LANES {
            let (is_bad, is_zero) = bad_and_no_return(x[l], y[l], z[l]);
            bad[l] += u32::from(is_bad);
            zero[l] += u32::from(is_zero);
            oa[l] = atan2_lane(y[l], x[l]);
            od[l] = (x[l] * x[l] + y[l] * y[l]).sqrt();
            of[l] = z[l] / od[l].max(1e-6);
        }
        if n == LANES {
            // A copy of known length, inlined as vector stores (a `memmove` call per slice of
            // unknown length cost 1 % of a KITTI frame's samples).
            az.extend_from_slice(&oa);
            dist.extend_from_slice(&od);
            fine.extend_from_slice(&of);
        } else {
            az.extend_from_slice(&oa[..n]);
            dist.extend_from_slice(&od[..n]);
            fine.extend_from_slice(&of[..n]);
        }
    }
    let total = |c: [u32; LANES]| c.iter().map(|&c| c as usize).sum::<usize>();
    ((az, dist, fine), (total(bad), total(zero)))
}

/// [`fast_atan2`] with its branches as selects (it vectorizes); the same bits for every input.
#[inline(always)]
pub(crate) fn atan2_lane(y: f32, x: f32) -> f32 {
    use std::f32::consts::{FRAC_PI_2, PI};
    let (ax, ay) = (x.abs(), y.abs());
    let swap = ay > ax;
    let (num, den) = if swap { (ax, ay) } else { (ay, ax) };
    let t = num / if den == 0.0 { 1.0 } else { den };
    let t2 = t * t;
    let mut a = t
        * (0.999_996_1
            + t2 * (-0.333_172_8
                + t2 * (0.198_069_7
                    + t2 * (-0.132_299_9 + t2 * (0.079_560_77 + t2 * (-0.033_548_71 + t2 * 0.006_793_221))))));
    a = if swap { FRAC_PI_2 - a } else { a };
    a = if x < 0.0 { PI - a } else { a };
    let a = if y < 0.0 { -a } else { a };
    let signed_pi = if y.is_sign_negative() { -PI } else { PI };
    let on_axis = if x.is_sign_negative() { signed_pi } else { 0.0f32.copysign(y) };
    if den == 0.0 { on_axis } else { a }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;

    #[test]
    fn lanes_give_fast_atan2_bit_for_bit() {
        let specials = [0.0f32, -0.0, 1.0, -1.0, 1e-30, -1e-30, 3.5, -7.25, 1e6, f32::MIN_POSITIVE];
        let mut pts = Vec::new();
        for &x in &specials {
            for &y in &specials {
                pts.push(Vec3::new(x, y, 0.5));
            }
        }
        // A dense sweep of directions and lengths (a deterministic sequence).
        for i in 0..20_000 {
            let t = i as f32 * 0.000_314_159_27 * 1.000_37;
            let r = 0.3 + (i % 97) as f32 * 0.71;
            pts.push(Vec3::new(r * t.cos(), r * t.sin(), -1.7));
        }
        let valid: Vec<u32> = (0..pts.len() as u32).rev().collect();
        let (az, dist, fine) = polar(&pts, Some(&valid));
        let (all_az, _, _) = polar(&pts, None);
        for (j, &k) in valid.iter().enumerate() {
            assert_eq!(all_az[k as usize].to_bits(), az[j].to_bits());
        }
        for (j, &k) in valid.iter().enumerate() {
            let p = pts[k as usize];
            assert_eq!(az[j].to_bits(), fast_atan2(p.y, p.x).to_bits(), "azimuth of {p:?}");
            let d = (p.x * p.x + p.y * p.y).sqrt();
            assert_eq!(dist[j].to_bits(), d.to_bits());
            assert_eq!(fine[j].to_bits(), (p.z / d.max(1e-6)).to_bits());
        }
        // The counts of a pass over every point: bad points and no-returns, none in the padding
        // lanes of a last partial block (the cloud's length is not a multiple of the lanes).
        let mut odd = pts[..1001].to_vec();
        odd[3] = Vec3::new(f32::NAN, 1.0, 1.0);
        odd[17] = Vec3::new(1.0, f32::NEG_INFINITY, 1.0);
        odd[18] = Vec3::new(1.0, 1.0, f32::INFINITY);
        odd[500] = Vec3::ZERO;
        odd[1000] = Vec3::new(0.0, -0.0, 0.0);
        assert_eq!(polar_counting(&odd, None).1, (3, 2));
        assert_eq!(polar_counting(&odd[..999], None).1, (3, 1));
        let (polar_all, counts) = polar_counting(&pts, None);
        assert_eq!((polar_all.0.len(), counts), (pts.len(), (0, 0)));
        // Spot values against libm.
        let (az, _, _) = polar(&[Vec3::new(-1.0, 0.0, 0.0), Vec3::new(0.0, -2.0, 0.0), Vec3::new(1.0, 1.0, 0.0)], None);
        assert!((az[0] - std::f32::consts::PI).abs() < 1e-6);
        assert!((az[1] + std::f32::consts::FRAC_PI_2).abs() < 1e-6);
        assert!((az[2] - std::f32::consts::FRAC_PI_4).abs() < 1e-6);
    }
}
