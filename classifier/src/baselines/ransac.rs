//! RANSAC plane fitting as PCL's `SACSegmentation` with `SACMODEL_PLANE` and `SAC_RANSAC` does it:
//! sample three distinct points, reject collinear samples, count the points within the distance
//! threshold of the plane, keep the best model; stop after `max_iterations` or earlier when the
//! adaptive count `log(1 - p) / log(1 - w^3)` (PCL's probability `p = 0.99`, `w` the best inlier
//! fraction so far) is reached; then refit the plane to the inliers by least squares
//! (`optimize_coefficients`, PCL's default) and take the points within the threshold of the refit
//! plane as ground. Every return of every echo plane takes part. The sampler is a
//! `Xoshiro256PlusPlus` seeded per frame with `seed + frame index`.

use glam::{DVec3, Vec3};
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

use crate::error::{ClassifyError, Result, check_cloud, is_valid};

/// Parameters of the plane fit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RansacParams {
    /// Inlier distance, metres (0.15 in the comparison).
    pub distance_threshold_m: f32,
    /// Most iterations (1000 in the comparison).
    pub max_iterations: usize,
    /// Probability of having drawn one outlier-free sample (PCL: 0.99).
    pub probability: f64,
    /// Base seed of the sampler.
    pub seed: u64,
}

impl Default for RansacParams {
    fn default() -> Self {
        Self { distance_threshold_m: 0.15, max_iterations: 1000, probability: 0.99, seed: 0 }
    }
}

/// A plane `normal . p + offset = 0` with a unit normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    /// Unit normal.
    pub normal: Vec3,
    /// Offset.
    pub offset: f32,
}

impl Plane {
    /// Signed distance of `p` from the plane.
    pub fn distance(&self, p: Vec3) -> f32 {
        self.normal.dot(p) + self.offset
    }
}

/// Fits a plane to `points` (invalid ones skipped); `None` when fewer than 3 usable points.
pub fn fit_plane(points: &[Vec3], params: &RansacParams, frame: u64) -> Result<Option<(Plane, Vec<bool>)>> {
    if !(params.distance_threshold_m.is_finite() && params.distance_threshold_m > 0.0) {
        return Err(ClassifyError::invalid("distance_threshold_m", params.distance_threshold_m, "finite, > 0"));
    }
    if params.max_iterations == 0 {
        return Err(ClassifyError::invalid("max_iterations", 0, ">= 1"));
    }
    if !(params.probability > 0.0 && params.probability < 1.0) {
        return Err(ClassifyError::invalid("probability", params.probability, "0 < p < 1"));
    }
    let valid: Vec<usize> = (0..points.len()).filter(|&i| is_valid(points[i])).collect();
    if valid.len() < 3 {
        return Ok(None);
    }
    let thr = params.distance_threshold_m;
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(params.seed.wrapping_add(frame));
    let mut best: Option<(Plane, usize)> = None;
    let mut needed = params.max_iterations as f64;
    let mut it = 0usize;
    let mut skipped = 0usize;
    while (it as f64) < needed && it < params.max_iterations && skipped < 10 * params.max_iterations {
        let a = valid[rng.random_range(0..valid.len())];
        let b = valid[rng.random_range(0..valid.len())];
        let c = valid[rng.random_range(0..valid.len())];
        let Some(plane) = plane_through(points[a], points[b], points[c]) else {
            skipped += 1;
            continue;
        };
        it += 1;
        let count = valid.iter().filter(|&&i| plane.distance(points[i]).abs() <= thr).count();
        if best.is_none_or(|(_, bc)| count > bc) {
            best = Some((plane, count));
            let w = count as f64 / valid.len() as f64;
            let p_no_outliers = 1.0 - w * w * w;
            needed = if p_no_outliers <= f64::EPSILON {
                0.0
            } else {
                ((1.0 - params.probability).ln() / p_no_outliers.ln()).max(1.0)
            };
        }
    }
    let Some((plane, _)) = best else {
        return Ok(None);
    };
    let inliers: Vec<Vec3> = valid.iter().map(|&i| points[i]).filter(|&p| plane.distance(p).abs() <= thr).collect();
    let plane = least_squares_plane(&inliers).unwrap_or(plane);
    let mask = points.iter().map(|&p| is_valid(p) && plane.distance(p).abs() <= thr).collect();
    Ok(Some((plane, mask)))
}

/// The plane through three points, `None` if they are (nearly) collinear or coincide.
fn plane_through(a: Vec3, b: Vec3, c: Vec3) -> Option<Plane> {
    let n = (b - a).cross(c - a);
    let l = n.length();
    if l <= 1e-6 * (b - a).length().max(1e-6) * (c - a).length().max(1e-6) || !l.is_finite() {
        return None;
    }
    let normal = n / l;
    Some(Plane { normal, offset: -normal.dot(a) })
}

/// Least-squares plane (smallest principal axis of the covariance), `None` if degenerate.
pub fn least_squares_plane(points: &[Vec3]) -> Option<Plane> {
    if points.len() < 3 {
        return None;
    }
    let mean = points.iter().fold(DVec3::ZERO, |s, p| s + p.as_dvec3()) / points.len() as f64;
    let (mut xx, mut xy, mut xz, mut yy, mut yz, mut zz) = (0f64, 0f64, 0f64, 0f64, 0f64, 0f64);
    for p in points {
        let d = p.as_dvec3() - mean;
        xx += d.x * d.x;
        xy += d.x * d.y;
        xz += d.x * d.z;
        yy += d.y * d.y;
        yz += d.y * d.z;
        zz += d.z * d.z;
    }
    let normal = smallest_eigenvector([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])?;
    let normal = normal.as_vec3();
    Some(Plane { normal, offset: -normal.dot(mean.as_vec3()) })
}

/// Unit eigenvector of the smallest eigenvalue of a symmetric 3 x 3 matrix.
fn smallest_eigenvector(m: [[f64; 3]; 3]) -> Option<DVec3> {
    // Eigenvalues by the trigonometric method for symmetric matrices.
    let p1 = m[0][1].powi(2) + m[0][2].powi(2) + m[1][2].powi(2);
    let q = (m[0][0] + m[1][1] + m[2][2]) / 3.0;
    let p2 = (m[0][0] - q).powi(2) + (m[1][1] - q).powi(2) + (m[2][2] - q).powi(2) + 2.0 * p1;
    let p = (p2 / 6.0).sqrt();
    if p <= 0.0 || !p.is_finite() {
        return None;
    }
    let b = |i: usize, j: usize| (m[i][j] - if i == j { q } else { 0.0 }) / p;
    let det_b = b(0, 0) * (b(1, 1) * b(2, 2) - b(1, 2) * b(2, 1)) - b(0, 1) * (b(1, 0) * b(2, 2) - b(1, 2) * b(2, 0))
        + b(0, 2) * (b(1, 0) * b(2, 1) - b(1, 1) * b(2, 0));
    let phi = (det_b / 2.0).clamp(-1.0, 1.0).acos() / 3.0;
    let smallest = q + 2.0 * p * (phi + 2.0 * std::f64::consts::PI / 3.0).cos();
    let row = |i: usize| DVec3::new(m[i][0], m[i][1], m[i][2]) - DVec3::new(0.0, 0.0, 0.0).with_element(i, smallest);
    let (r0, r1, r2) = (row(0), row(1), row(2));
    let candidates = [r0.cross(r1), r0.cross(r2), r1.cross(r2)];
    let best = candidates.into_iter().max_by(|a, b| a.length_squared().total_cmp(&b.length_squared()))?;
    let l = best.length();
    (l > 0.0 && l.is_finite()).then(|| best / l)
}

trait WithElement {
    fn with_element(self, i: usize, v: f64) -> Self;
}

impl WithElement for DVec3 {
    fn with_element(mut self, i: usize, v: f64) -> Self {
        self[i] = v;
        self
    }
}

/// Classifies every cell of `cloud` (all planes): ground = inlier of the fitted plane.
pub fn classify(cloud: &sim::OrderedCloud, params: &RansacParams, frame: u64) -> Result<Vec<bool>> {
    check_cloud(cloud)?;
    Ok(fit_plane(&cloud.point_in_vehicle, params, frame)?.map_or_else(|| vec![false; cloud.len()], |(_, m)| m))
}
