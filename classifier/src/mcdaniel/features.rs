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
//! With N < 3 the plane is not determined: f5 = 1 (level) and f6 = 0. Heights are the vehicle
//! frame's z (z = 0 on the ground under the vehicle origin).

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
    let (f5, f6) = if n < 3 {
        (1.0, 0.0)
    } else {
        let mut cov = DMat3::ZERO;
        for p in pts {
            let d = *p - mean;
            cov += DMat3::from_cols(d * d.x, d * d.y, d * d.z);
        }
        cov *= 1.0 / nf;
        plane_normal_z_and_rss(cov)
    };
    [n as f32, min_z - z, z, mean.z as f32, f5 as f32, f6 as f32]
}

/// `(|n_z|, smallest eigenvalue)` of a covariance matrix: the z-component of the plane normal (the
/// eigenvector of the smallest eigenvalue) and the mean squared orthogonal residual.
fn plane_normal_z_and_rss(cov: DMat3) -> (f64, f64) {
    let eig = DSymmetricEigen3::new(cov);
    let normal = eig.eigenvectors.x_axis;
    let len = normal.length();
    let nz = if len > 0.0 && len.is_finite() { (normal.z / len).abs() } else { 1.0 };
    (nz, eig.eigenvalues.x.max(0.0))
}

/// f1-f6 of every candidate, in candidate order (parallel; each candidate is independent, so the
/// result does not depend on the thread count).
pub fn all_local_features(columns: &Columns) -> Vec<[f32; 6]> {
    (0..columns.len()).into_par_iter().with_min_len(256).map(|k| local_features(columns, k)).collect()
}
