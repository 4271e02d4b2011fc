//! Sensor origins in the vehicle frame, estimated from a cloud's returns.
//!
//! An [`sim::OrderedCloud`] stores each return's point (vehicle frame) and range, but not where the
//! beam started. Every return of one sensor satisfies `|p - s|^2 = r^2` for the sensor's origin
//! `s`; expanding gives `|p|^2 - 2 p.s + |s|^2 = r^2`, and subtracting the mean of these equations
//! over the sensor's returns removes `|s|^2`:
//!
//! `2 (p - p_mean) . s = (|p|^2 - r^2) - mean(|p|^2 - r^2)`,
//!
//! linear in `s`. [`estimate_origin`] solves it by linear least squares (normal equations in
//! `f64`, points centred first). Range noise of a few centimetres moves the estimate by far less
//! than that on a frame of thousands of returns spread in direction (the right-hand side's noise is
//! `2 r dr`, averaged over all returns). A sensor whose beam origin moves during the frame (a
//! nodding laser's optical centre on its lever arm, a moving vehicle) gets the least-squares
//! compromise of its origins; pass known origins (e.g. from a manifest's `vehicle_from_sensor`)
//! where that matters, with [`origins_for_cloud`]. The fit is unchanged by a constant added to
//! every `r^2`, so a beam origin offset perpendicular to every beam is invisible to it: the nodding
//! UTM-30LX's optical centre rides a 5 cm lever arm at right angles to its beams
//! (`|p - axis|^2 = r^2 + 0.05^2`), and the estimate is the tilt axis (measured within 1 mm of
//! (0, 0, 0.55) on the forests).

use glam::{DMat3, DVec3, Vec3};

use crate::error::{ClassifyError, Result};

/// Fewest returns a sensor needs for an estimate.
pub const MIN_RETURNS: usize = 16;

/// Estimates one sensor's origin from its returns' `(point, range)` pairs (vehicle frame, metres).
/// Pairs with a non-finite point or range are skipped. `None` when fewer than [`MIN_RETURNS`]
/// usable pairs remain or their points are (nearly) coplanar through a line of sight, so that the
/// origin is not determined.
pub fn estimate_origin(pairs: impl IntoIterator<Item = (Vec3, f32)> + Clone) -> Option<Vec3> {
    // First pass: the mean point, to centre the coordinates (keeps |p|^2 well conditioned).
    let mut n = 0usize;
    let mut sum = DVec3::ZERO;
    for (p, r) in pairs.clone() {
        if p.is_finite() && r.is_finite() {
            n += 1;
            sum += p.as_dvec3();
        }
    }
    if n < MIN_RETURNS {
        return None;
    }
    let centre = sum / n as f64;
    // Second pass: with q = p - centre and b = |q|^2 - r^2, accumulate the normal equations of
    // 2 (q - q_mean) . u = b - b_mean, where u = s - centre.
    let mut sum_q = DVec3::ZERO;
    let mut sum_b = 0.0f64;
    let mut sum_qq = DMat3::ZERO;
    let mut sum_qb = DVec3::ZERO;
    for (p, r) in pairs {
        if !(p.is_finite() && r.is_finite()) {
            continue;
        }
        let q = p.as_dvec3() - centre;
        let b = q.length_squared() - f64::from(r) * f64::from(r);
        sum_q += q;
        sum_b += b;
        sum_qq += outer(q, q);
        sum_qb += q * b;
    }
    let nf = n as f64;
    let mean_q = sum_q / nf;
    // Covariances: sum (q - mq)(q - mq)^T and sum (q - mq)(b - mb).
    let cov_qq = sum_qq - outer(mean_q, sum_q);
    let cov_qb = sum_qb - mean_q * sum_b;
    // Normal equations of the least squares: 4 cov_qq u = 2 cov_qb.
    let a = cov_qq * 2.0;
    let scale = a.x_axis.x + a.y_axis.y + a.z_axis.z;
    if scale.is_nan() || scale <= 0.0 || a.determinant().abs() <= 1e-12 * scale * scale * scale {
        return None;
    }
    let u = a.inverse() * cov_qb;
    let s = u + centre;
    s.is_finite().then(|| s.as_vec3())
}

fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

/// Whether cell `i` is a return with a finite point and a sensor id.
fn usable(cloud: &sim::OrderedCloud, i: usize) -> bool {
    cloud.has_return(i) && cloud.sensor[i] != u8::MAX && cloud.point_in_vehicle[i].is_finite()
}

/// Estimates the origin of every sensor of `cloud`, indexed by sensor id (`0..=max id` seen on a
/// usable return: finite point and range); `None` for ids without enough returns (see [`estimate_origin`]).
pub fn estimate_origins(cloud: &sim::OrderedCloud) -> Vec<Option<Vec3>> {
    let max_id = (0..cloud.len()).filter(|&i| usable(cloud, i)).map(|i| cloud.sensor[i]).max();
    let Some(max_id) = max_id else { return Vec::new() };
    (0..=max_id)
        .map(|id| {
            let pairs = (0..cloud.len())
                .filter(move |&i| cloud.sensor[i] == id && usable(cloud, i))
                .map(move |i| (cloud.point_in_vehicle[i], cloud.range_m[i]));
            estimate_origin(pairs)
        })
        .collect()
}

/// The origin of every sensor with a return in `cloud`, indexed by sensor id: `known[id]` where the
/// caller passes known origins, otherwise [`estimate_origins`]. Errors when `known` is too short for
/// a sensor id of the cloud, holds a non-finite origin, or an origin cannot be estimated.
pub fn origins_for_cloud(cloud: &sim::OrderedCloud, known: Option<&[Vec3]>) -> Result<Vec<Vec3>> {
    if let Some(known) = known {
        let max_id = (0..cloud.len()).filter(|&i| usable(cloud, i)).map(|i| cloud.sensor[i] as usize).max();
        if let Some(max_id) = max_id
            && known.len() <= max_id
        {
            return Err(ClassifyError::invalid(
                "sensor_origins",
                format!("{} origins", known.len()),
                "one origin per sensor id of the cloud's returns",
            ));
        }
        if let Some(bad) = known.iter().find(|o| !o.is_finite()) {
            return Err(ClassifyError::invalid("sensor_origins", bad, "finite coordinates, metres"));
        }
        return Ok(known.to_vec());
    }
    estimate_origins(cloud)
        .into_iter()
        .enumerate()
        .map(|(id, o)| {
            // Ids without returns get a placeholder that no segment uses.
            let has = (0..cloud.len()).any(|i| cloud.sensor[i] as usize == id && usable(cloud, i));
            match (o, has) {
                (Some(o), _) => Ok(o),
                (None, false) => Ok(Vec3::ZERO),
                (None, true) => Err(ClassifyError::Missing {
                    method: "sensor_origin",
                    what: "at least 16 returns spread in direction per sensor to estimate its origin (or known origins)",
                }),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_pairs_give_the_origin() {
        let s = Vec3::new(1.0, -2.0, 0.5);
        let mut pairs = Vec::new();
        for k in 0..100 {
            let a = k as f32 * 0.37;
            let e = (k % 7) as f32 * 0.1 - 0.3;
            let d = Vec3::new(a.cos() * e.cos(), a.sin() * e.cos(), e.sin());
            let r = 3.0 + (k % 11) as f32;
            pairs.push((s + d * r, r));
        }
        let est = estimate_origin(pairs.iter().copied()).unwrap();
        assert!((est - s).length() < 1e-3, "{est}");
    }

    #[test]
    fn too_few_or_degenerate_pairs_give_none() {
        let pairs = [(Vec3::X, 1.0f32); 10];
        assert_eq!(estimate_origin(pairs.iter().copied()), None);
        let pairs = [(Vec3::X, 1.0f32); 100];
        assert_eq!(estimate_origin(pairs.iter().copied()), None);
    }
}
