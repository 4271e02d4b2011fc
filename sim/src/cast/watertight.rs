//! Watertight ray/triangle intersection (Woop, Benthin and Wald, "Watertight Ray/Triangle
//! Intersection", JCGT 2(1), 2013).
//!
//! The ray is turned into a per-ray precomputation ([`RayPre`]): the dimension where its direction
//! is largest becomes `kz`, the other two `kx`, `ky` (swapped when `dir[kz] < 0` to keep the
//! winding), and a shear `Sx, Sy, Sz` maps the ray onto the +z axis through the origin. Each
//! triangle vertex is translated and sheared the same way, and the three 2D edge functions `U, V, W`
//! decide whether the origin of the sheared plane lies inside the triangle. A shared edge or vertex
//! of two triangles gets exactly the same sheared coordinates from both (same vertex values, same
//! operations, no fused multiply-add), so its edge function is the same number with opposite sign:
//! a ray through it is inside at least one of the two. When an edge function is exactly `0.0` the
//! three are recomputed in `f64` (a product of two `f32` is exact in `f64`), so that the sign of a
//! near-zero edge function is never a rounding accident. Zero counts as inside; both windings hit
//! (no backface culling).

use glam::Vec3;

use super::Ray;

/// A ray prepared for the watertight test: permutation, shear and range.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayPre {
    /// Ray origin, metres.
    pub origin: Vec3,
    /// Axis of the largest absolute direction component.
    pub kz: usize,
    /// First of the two other axes.
    pub kx: usize,
    /// Second of the two other axes.
    pub ky: usize,
    /// Shear x: `dir[kx] / dir[kz]`.
    pub sx: f32,
    /// Shear y: `dir[ky] / dir[kz]`.
    pub sy: f32,
    /// Scale z: `1 / dir[kz]`.
    pub sz: f32,
    /// Largest distance accepted, metres.
    pub t_max: f32,
}

impl RayPre {
    /// Prepares `ray`. The direction must be non-zero and finite (unit length in the casters).
    #[inline]
    pub fn new(ray: &Ray) -> Self {
        let d = ray.dir;
        let a = d.abs();
        let kz = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        if d[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        let sz = 1.0 / d[kz];
        Self { origin: ray.origin, kz, kx, ky, sx: d[kx] * sz, sy: d[ky] * sz, sz, t_max: ray.t_max }
    }

    /// Distance `t` in `(0, t_limit]` where the ray meets triangle `a b c`, or `None`.
    /// `t_limit` is usually `t_max` or the closest hit found so far.
    #[inline(always)]
    pub fn intersect(&self, a: Vec3, b: Vec3, c: Vec3, t_limit: f32) -> Option<f32> {
        let (kx, ky, kz) = (self.kx, self.ky, self.kz);
        let a = a - self.origin;
        let b = b - self.origin;
        let c = c - self.origin;
        let (az, bz, cz) = (a[kz], b[kz], c[kz]);
        let ax = a[kx] - self.sx * az;
        let ay = a[ky] - self.sy * az;
        let bx = b[kx] - self.sx * bz;
        let by = b[ky] - self.sy * bz;
        let cx = c[kx] - self.sx * cz;
        let cy = c[ky] - self.sy * cz;

        let mut u = cx * by - cy * bx;
        let mut v = ax * cy - ay * cx;
        let mut w = bx * ay - by * ax;
        if u == 0.0 || v == 0.0 || w == 0.0 {
            let (ax, ay, bx, by, cx, cy) = (ax as f64, ay as f64, bx as f64, by as f64, cx as f64, cy as f64);
            u = (cx * by - cy * bx) as f32;
            v = (ax * cy - ay * cx) as f32;
            w = (bx * ay - by * ax) as f32;
        }
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v + w;
        if det == 0.0 {
            return None;
        }
        let t_scaled = u * (self.sz * az) + v * (self.sz * bz) + w * (self.sz * cz);
        Self::distance(t_scaled, det, t_limit)
    }

    /// The last step of [`RayPre::intersect`]: the distance `t_scaled / det` (`det` non-zero) when
    /// it lies in `(0, t_limit]`, else `None`. Shared with the four-triangle test of `tri_pack.rs`,
    /// so both decide with the same operations.
    #[inline(always)]
    pub(super) fn distance(t_scaled: f32, det: f32, t_limit: f32) -> Option<f32> {
        // 0 < t_scaled / det <= t_limit, without dividing.
        let in_range = if det > 0.0 {
            t_scaled > 0.0 && t_scaled <= t_limit * det
        } else {
            t_scaled < 0.0 && t_scaled >= t_limit * det
        };
        if !in_range {
            return None;
        }
        let t = t_scaled / det;
        (t > 0.0 && t <= t_limit).then_some(t)
    }
}

/// One-shot convenience: distance where `ray` meets triangle `[a, b, c]` within `(0, ray.t_max]`.
pub fn intersect_triangle(ray: &Ray, [a, b, c]: [Vec3; 3]) -> Option<f32> {
    RayPre::new(ray).intersect(a, b, c, ray.t_max)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ray(o: Vec3, d: Vec3) -> Ray {
        Ray { origin: o, dir: d.normalize(), t_max: 1000.0 }
    }

    #[test]
    fn hits_centre_from_both_sides() {
        let tri = [Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0)];
        let t = intersect_triangle(&ray(Vec3::new(0.25, 0.25, 5.0), -Vec3::Z), tri).unwrap();
        assert!((t - 5.0).abs() < 1e-6);
        let t = intersect_triangle(&ray(Vec3::new(0.25, 0.25, -3.0), Vec3::Z), tri).unwrap();
        assert!((t - 3.0).abs() < 1e-6);
    }

    #[test]
    fn misses_outside_behind_and_beyond() {
        let tri = [Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0)];
        assert_eq!(intersect_triangle(&ray(Vec3::new(0.6, 0.6, 5.0), -Vec3::Z), tri), None);
        assert_eq!(intersect_triangle(&ray(Vec3::new(0.25, 0.25, 5.0), Vec3::Z), tri), None);
        let mut r = ray(Vec3::new(0.25, 0.25, 5.0), -Vec3::Z);
        r.t_max = 4.999;
        assert_eq!(intersect_triangle(&r, tri), None);
        r.t_max = 5.0;
        assert_eq!(intersect_triangle(&r, tri), Some(5.0));
        // Parallel to the plane.
        assert_eq!(intersect_triangle(&ray(Vec3::new(-1.0, 0.25, 0.0), Vec3::X), tri), None);
    }

    #[test]
    fn shared_edge_and_vertex_are_closed() {
        // Two triangles sharing the diagonal (0,0)-(1,1); rays through points of the shared diagonal.
        // (Interior vertices shared by six triangles are tested in `tests/caster.rs`.)
        let (p00, p10, p11, p01) =
            (Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(1.0, 1.0, 0.0), Vec3::new(0.0, 1.0, 0.0));
        for target in [Vec3::new(0.5, 0.5, 0.0), Vec3::new(0.25, 0.25, 0.0), Vec3::new(0.875, 0.875, 0.0)] {
            for o in [Vec3::new(0.3, -2.0, 4.0), Vec3::new(-7.0, 3.0, 1.0), Vec3::new(0.5, 0.5, 9.0)] {
                let r = ray(o, target - o);
                let h1 = intersect_triangle(&r, [p00, p10, p11]);
                let h2 = intersect_triangle(&r, [p00, p11, p01]);
                assert!(h1.is_some() || h2.is_some(), "ray {o} -> {target} leaked");
            }
        }
    }
}
