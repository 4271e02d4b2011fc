//! Feature f8, the ray-tracing score (McDaniel et al., Fig. 4): for the cubic voxel containing a
//! candidate `P_ij`, the number of sensor-to-return line segments passing under it. The ground
//! cannot lie above a beam, so candidates with beams below them are unlikely to be ground.
//!
//! Definitions. Voxels are `cell_m` cubes aligned with the columns, layer `k` spanning
//! `k * cell_m <= z < (k + 1) * cell_m` (vehicle frame, z = 0 on the ground under the vehicle
//! origin). Every return of the cloud (all echo planes, candidate or not, inside the stage 1
//! extent or not) gives one segment from its sensor's origin to its point. A segment passes
//! *under* the voxel `(i, j, k)` of a candidate iff it visits a voxel `(i, j, k')` of the same column
//! with `k' < k`, i.e. a 3-D voxel walk (Amanatides & Woo) of the segment enters the candidate's
//! column below the candidate's voxel.
//!
//! Exact 2-D walk. The part of a segment inside one column's prism is one sub-segment (the prism
//! is convex), along which z is linear in the segment parameter, so the voxels the 3-D walk visits
//! in that column are exactly the layers from `floor(z_lo / cell_m)` to `floor(z_hi / cell_m)`,
//! where `z_lo`, `z_hi` are the z at the sub-segment's ends. "Visits a layer below `k`" is therefore
//! `z_lo < k * cell_m`. The walk steps through the columns the segment crosses (Amanatides & Woo
//! in 2-D, in `f64`), computes `z_lo` from the entry and exit parameters and compares it with the
//! candidate's voxel floor. A segment touching a column only at a corner (a zero-length visit)
//! does not count. Segments are clipped to the grid first (columns off the grid hold no candidate).
//!
//! Counts are integers summed over per-thread partial counts, so the result does not depend on the
//! thread count.

use glam::{DVec3, Vec3};
use rayon::prelude::*;

use super::columns::{Columns, NONE};

/// f8 of every candidate, in candidate order. `origins[id]` is the origin (vehicle frame) of sensor
/// `id`; returns of sensors without an entry are skipped.
pub fn ray_trace_counts(cloud: &sim::OrderedCloud, columns: &Columns, origins: &[Vec3]) -> Vec<u32> {
    let m = columns.len();
    if m == 0 {
        return Vec::new();
    }
    // Per grid column, the floor of its candidate's voxel and the candidate; -inf for an empty
    // column (never counts).
    let cell = f64::from(columns.cell_m);
    let column: Vec<(f64, u32)> = columns
        .candidate_of_column
        .iter()
        .map(|&k| {
            if k == NONE {
                (f64::NEG_INFINITY, 0)
            } else {
                (f64::from(columns.layer(columns.point_in_vehicle[k as usize].z)) * cell, k)
            }
        })
        .collect();
    let walker = Walker {
        inv_cell: 1.0 / cell,
        i0: f64::from(columns.i0),
        j0: f64::from(columns.j0),
        ni: columns.ni,
        nj: columns.nj,
        column: &column,
    };
    let n = cloud.len();
    (0..n)
        .into_par_iter()
        .with_min_len(8192)
        .fold(
            || vec![0u32; m],
            |mut acc, c| {
                if !cloud.has_return(c) {
                    return acc;
                }
                let p = cloud.point_in_vehicle[c];
                let Some(o) = origins.get(cloud.sensor[c] as usize) else { return acc };
                if !p.is_finite() {
                    return acc;
                }
                walker.walk(o.as_dvec3(), p.as_dvec3(), &mut acc);
                acc
            },
        )
        .reduce(
            || vec![0u32; m],
            |mut a, b| {
                for (x, y) in a.iter_mut().zip(&b) {
                    *x += *y;
                }
                a
            },
        )
}

struct Walker<'a> {
    inv_cell: f64,
    i0: f64,
    j0: f64,
    ni: usize,
    nj: usize,
    /// Per grid column: (floor of the candidate's voxel, candidate).
    column: &'a [(f64, u32)],
}

impl Walker<'_> {
    /// Walks the segment `a -> b` over the grid's columns, counting it for every candidate it
    /// passes under.
    fn walk(&self, a: DVec3, b: DVec3, counts: &mut [u32]) {
        // Grid coordinates: u along i, v along j; the grid covers [0, ni) x [0, nj).
        let u0 = a.x * self.inv_cell - self.i0;
        let v0 = a.y * self.inv_cell - self.j0;
        let du = b.x * self.inv_cell - self.i0 - u0;
        let dv = b.y * self.inv_cell - self.j0 - v0;
        let (z0, dz) = (a.z, b.z - a.z);
        // Clip t in [0, 1] to the grid (slab method).
        let (mut t_lo, mut t_hi) = (0.0f64, 1.0f64);
        for (s0, ds, size) in [(u0, du, self.ni as f64), (v0, dv, self.nj as f64)] {
            if ds == 0.0 {
                if s0 < 0.0 || s0 >= size {
                    return;
                }
            } else {
                let ta = (0.0 - s0) / ds;
                let tb = (size - s0) / ds;
                let (t1, t2) = if ta < tb { (ta, tb) } else { (tb, ta) };
                t_lo = t_lo.max(t1);
                t_hi = t_hi.min(t2);
            }
        }
        if t_lo >= t_hi || t_lo.is_nan() || t_hi.is_nan() {
            return;
        }
        // Start column: the one the segment is in just after t_lo (a point a hair inside the
        // clipped range avoids landing on a boundary), clamped onto the grid.
        let t_start = t_lo;
        let probe = t_lo + (t_hi - t_lo) * 1e-9;
        let mut cu = ((u0 + probe * du).floor() as i64).clamp(0, self.ni as i64 - 1);
        let mut cv = ((v0 + probe * dv).floor() as i64).clamp(0, self.nj as i64 - 1);
        let step_u: i64 = if du > 0.0 { 1 } else { -1 };
        let step_v: i64 = if dv > 0.0 { 1 } else { -1 };
        let next_t = |c: i64, s0: f64, ds: f64| -> f64 {
            if ds > 0.0 {
                (c as f64 + 1.0 - s0) / ds
            } else if ds < 0.0 {
                (c as f64 - s0) / ds
            } else {
                f64::INFINITY
            }
        };
        let delta_u = if du != 0.0 { 1.0 / du.abs() } else { f64::INFINITY };
        let delta_v = if dv != 0.0 { 1.0 / dv.abs() } else { f64::INFINITY };
        let mut t_max_u = next_t(cu, u0, du);
        let mut t_max_v = next_t(cv, v0, dv);
        let mut t_cur = t_start;
        // Grid column index, kept up to date as the walk steps.
        let nj = self.nj as i64;
        let mut g = cu * nj + cv;
        let step_g_u = step_u * nj;
        loop {
            let t_exit = t_max_u.min(t_max_v).min(t_hi);
            if t_exit > t_cur {
                // z is linear in t: the lower end is the exit going down, the entry going up.
                let z_lo = z0 + if dz <= 0.0 { t_exit } else { t_cur } * dz;
                let (floor, k) = self.column[g as usize];
                if z_lo < floor {
                    counts[k as usize] += 1;
                }
            }
            if t_exit >= t_hi {
                break;
            }
            t_cur = t_exit;
            if t_max_u < t_max_v {
                cu += step_u;
                g += step_g_u;
                t_max_u += delta_u;
            } else {
                cv += step_v;
                g += step_v;
                t_max_v += delta_v;
            }
            if cu < 0 || cv < 0 || cu >= self.ni as i64 || cv >= nj {
                break;
            }
        }
    }
}
