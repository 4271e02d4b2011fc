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
//! `f64`, points taken relative to one of them). Range noise of a few centimetres moves the estimate by far less
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
use rayon::prelude::*;

use crate::error::{ClassifyError, Result};

/// Fewest returns a sensor needs for an estimate.
pub const MIN_RETURNS: usize = 16;

/// Estimates one sensor's origin from its returns' `(point, range)` pairs (vehicle frame, metres).
/// Pairs with a non-finite point or range are skipped. `None` when fewer than [`MIN_RETURNS`]
/// usable pairs remain or their points are (nearly) coplanar through a line of sight, so that the
/// origin is not determined.
pub fn estimate_origin(pairs: impl IntoIterator<Item = (Vec3, f32)>) -> Option<Vec3> {
    let mut reference = None;
    let mut m = Moments::default();
    for (p, r) in pairs {
        if p.is_finite() && r.is_finite() {
            let c = *reference.get_or_insert(p.as_dvec3());
            m.add(p.as_dvec3() - c, f64::from(r));
        }
    }
    m.solve(reference?)
}

/// Sums of the least-squares problem of one sensor, over points `q = p - reference` (a fixed point
/// near the cloud keeps `|q|^2` well conditioned) with `b = |q|^2 - r^2`.
#[derive(Clone, Copy, Debug)]
struct Moments {
    n: usize,
    sum_q: DVec3,
    sum_b: f64,
    sum_qq: DMat3,
    sum_qb: DVec3,
}

impl Default for Moments {
    /// Empty sums (not `DMat3::default()`, which is the identity).
    fn default() -> Self {
        Self { n: 0, sum_q: DVec3::ZERO, sum_b: 0.0, sum_qq: DMat3::ZERO, sum_qb: DVec3::ZERO }
    }
}

impl Moments {
    fn add(&mut self, q: DVec3, r: f64) {
        let b = q.length_squared() - r * r;
        self.n += 1;
        self.sum_q += q;
        self.sum_b += b;
        self.sum_qq += outer(q, q);
        self.sum_qb += q * b;
    }

    fn merge(&mut self, o: &Moments) {
        self.n += o.n;
        self.sum_q += o.sum_q;
        self.sum_b += o.sum_b;
        self.sum_qq += o.sum_qq;
        self.sum_qb += o.sum_qb;
    }

    /// The origin: `2 (q - q_mean) . u = b - b_mean` with `u = s - reference`, by the normal
    /// equations `4 cov_qq u = 2 cov_qb`.
    fn solve(&self, reference: DVec3) -> Option<Vec3> {
        if self.n < MIN_RETURNS {
            return None;
        }
        let mean_q = self.sum_q / self.n as f64;
        let cov_qq = self.sum_qq - outer(mean_q, self.sum_q);
        let cov_qb = self.sum_qb - mean_q * self.sum_b;
        let a = cov_qq * 2.0;
        let scale = a.x_axis.x + a.y_axis.y + a.z_axis.z;
        if scale.is_nan() || scale <= 0.0 || a.determinant().abs() <= 1e-12 * scale * scale * scale {
            return None;
        }
        let s = a.inverse() * cov_qb + reference;
        s.is_finite().then(|| s.as_vec3())
    }
}

fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

/// Whether cell `i` is a return with a finite point and a sensor id.
fn usable(cloud: &sim::OrderedCloud, i: usize) -> bool {
    cloud.has_return(i) && cloud.sensor[i] != u8::MAX && cloud.point_in_vehicle[i].is_finite()
}

/// Cells per parallel chunk of [`sensor_moments`]: fixed, so the sums (and the origins) do not
/// depend on the thread count.
const CHUNK: usize = 1 << 15;

/// Per sensor id (`0..=max id` of a usable return), the sums of its returns, and the reference
/// point (the first usable return). Chunks are summed in parallel and merged in order.
fn sensor_moments(cloud: &sim::OrderedCloud) -> Option<(DVec3, Vec<Moments>)> {
    let first = (0..cloud.len()).find(|&i| usable(cloud, i))?;
    let reference = cloud.point_in_vehicle[first].as_dvec3();
    let partial: Vec<Vec<Moments>> = (0..cloud.len().div_ceil(CHUNK))
        .into_par_iter()
        .map(|chunk| {
            let mut m: Vec<Moments> = Vec::new();
            for i in chunk * CHUNK..((chunk + 1) * CHUNK).min(cloud.len()) {
                if !usable(cloud, i) {
                    continue;
                }
                let id = cloud.sensor[i] as usize;
                if m.len() <= id {
                    m.resize(id + 1, Moments::default());
                }
                m[id].add(cloud.point_in_vehicle[i].as_dvec3() - reference, f64::from(cloud.range_m[i]));
            }
            m
        })
        .collect();
    let mut total: Vec<Moments> = Vec::new();
    for m in &partial {
        if total.len() < m.len() {
            total.resize(m.len(), Moments::default());
        }
        for (t, x) in total.iter_mut().zip(m) {
            t.merge(x);
        }
    }
    Some((reference, total))
}

/// Estimates the origin of every sensor of `cloud`, indexed by sensor id (`0..=max id` seen on a
/// usable return: finite point and range); `None` for ids without enough returns (see
/// [`estimate_origin`]). Parallel; the result does not depend on the thread count.
pub fn estimate_origins(cloud: &sim::OrderedCloud) -> Vec<Option<Vec3>> {
    let Some((reference, moments)) = sensor_moments(cloud) else { return Vec::new() };
    moments.iter().map(|m| m.solve(reference)).collect()
}

/// The origin of every sensor with a return in `cloud`, indexed by sensor id: `known[id]` where the
/// caller passes known origins, otherwise [`estimate_origins`] (ids without returns get a
/// placeholder that no beam uses). Errors when `known` is too short for a sensor id of the cloud,
/// holds a non-finite origin, or an origin cannot be estimated.
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
    let Some((reference, moments)) = sensor_moments(cloud) else { return Ok(Vec::new()) };
    moments
        .iter()
        .map(|m| match m.solve(reference) {
            Some(o) => Ok(o),
            None if m.n == 0 => Ok(Vec3::ZERO),
            None => Err(ClassifyError::Missing {
                method: "sensor_origin",
                what: "at least 16 returns spread in direction per sensor to estimate its origin (or known origins)",
            }),
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
