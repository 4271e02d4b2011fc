//! Features f1-f6 of every candidate over its 3 x 3 column neighbourhood (the candidate's own
//! column included; only occupied columns count), after McDaniel et al., Eq. 1-7:
//!
//! * f1 = N, the number of occupied columns (1..=9);
//! * f2 = min z of the neighbourhood's candidates minus `z_ij` (Eq. 2 includes `z_ij`, so f2 <= 0);
//! * f3 = `z_ij`;
//! * f4 = mean z of the N candidates (Eq. 4);
//! * f5 = `|n_z|` of the unit normal `n` of the orthogonal least-squares (PCA) plane through the N
//!   candidates (Eq. 5-6; the absolute value makes the sign canonical);
//! * f6 = (1/N) sum of squared orthogonal residuals to that plane (Eq. 7): the smallest eigenvalue
//!   of the candidates' covariance matrix (normalised by N).
//!
//! Where Eq. 5 has no unique minimiser (N = 1, N = 2, or collinear candidates) every plane through
//! the points (N = 1) or containing their line fits with zero residual; f5 is then the largest
//! `|n_z|` among those minimisers: 1 for N = 1, `sqrt(1 - d_z^2)` for points along a unit direction
//! `d` (1 for a level pair, 0 for a vertical one), and f6 = 0. Numerically: the two smallest
//! eigenvalues of the covariance within `1e-6` of the largest (the cubic solver resolves a double
//! root to about `1e-8`). Heights are the vehicle frame's z (z = 0 on the ground under the vehicle
//! origin).

use glam::DMat3;
use glamx::DSymmetricEigen3;
use rayon::prelude::*;

use super::columns::Columns;

/// f1-f6 of one candidate.
pub fn local_features(columns: &Columns, k: usize) -> [f32; 6] {
    let (i, j) = columns.ij(k);
    let z = columns.point_in_vehicle[k].z;
    let mut pts = [glam::DVec3::ZERO; 9];
    let mut n = 0usize;
    let mut min_z = f32::INFINITY;
    for di in -1..=1 {
        for dj in -1..=1 {
            if let Some(q) = columns.candidate_at(i + di, j + dj) {
                let p = columns.point_in_vehicle[q];
                pts[n] = p.as_dvec3();
                n += 1;
                min_z = min_z.min(p.z);
            }
        }
    }
    let pts = &pts[..n];
    let nf = n as f64;
    let mean = pts.iter().copied().sum::<glam::DVec3>() / nf;
    let mut cov = DMat3::ZERO;
    for p in pts {
        let d = *p - mean;
        cov += DMat3::from_cols(d * d.x, d * d.y, d * d.z);
    }
    cov *= 1.0 / nf;
    let (f5, f6) = plane_normal_z_and_rss(cov);
    [n as f32, min_z - z, z, mean.z as f32, f5 as f32, f6 as f32]
}

/// `(|n_z|, smallest eigenvalue)` of a covariance matrix: the z-component of the plane normal (the
/// eigenvector of the smallest eigenvalue) and the mean squared orthogonal residual; see the module
/// docs for the degenerate cases.
pub fn plane_normal_z_and_rss(cov: DMat3) -> (f64, f64) {
    let eig = DSymmetricEigen3::new(cov);
    let (l1, l2, l3) = (eig.eigenvalues.x.max(0.0), eig.eigenvalues.y.max(0.0), eig.eigenvalues.z.max(0.0));
    let tiny = 1e-6 * l3;
    if l3 <= f64::MIN_POSITIVE || l3 - l1 <= tiny {
        // All points equal (or isotropic): every plane fits; the level one is among them.
        return (1.0, l1);
    }
    if l2 - l1 <= tiny {
        // Collinear: the normals of the minimising planes are those orthogonal to the line
        // direction e3; the most vertical has |n_z| = sqrt(1 - e3_z^2). e3 is the largest column of
        // cov - l1 I (rank one: (l3 - l1) e3 e3^T).
        let m = cov - DMat3::from_diagonal(glam::DVec3::splat(l1));
        let col =
            [m.x_axis, m.y_axis, m.z_axis].into_iter().max_by(|a, b| a.length_squared().total_cmp(&b.length_squared()));
        let e3 = col.unwrap_or(glam::DVec3::Z).normalize_or_zero();
        return ((1.0 - e3.z * e3.z).max(0.0).sqrt(), l1);
    }
    let normal = eig.eigenvectors.x_axis;
    let len = normal.length();
    let nz = if len > 0.0 && len.is_finite() { (normal.z / len).abs() } else { 1.0 };
    (nz, l1)
}

/// f1-f6 of every candidate, in candidate order (parallel; each candidate is independent, so the
/// result does not depend on the thread count).
pub fn all_local_features(columns: &Columns) -> Vec<[f32; 6]> {
    (0..columns.len()).into_par_iter().with_min_len(256).map(|k| local_features(columns, k)).collect()
}
