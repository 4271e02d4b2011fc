//! Four triangles of a leaf against one ray at once: the watertight test of [`super::watertight`]
//! with the four triangles in the four lanes of a SIMD vector (structure-of-arrays corners).
//!
//! Every lane does the operations [`RayPre::intersect`] does for its triangle, in the same order
//! (translate, shear, the three edge functions, their sum, the scaled distance; separate multiplies
//! and adds, no fused multiply-add), so a lane's numbers are the scalar test's numbers bit for bit.
//! The decisions that depend on the closest hit so far are then taken one lane after another, in
//! triangle order, by the scalar code itself ([`RayPre::distance`]); a lane whose edge function is
//! exactly zero (recomputed in `f64` by the scalar test) is handed to [`RayPre::intersect`] whole.
//! So a leaf reports exactly the hit the one-triangle-at-a-time loop reports.

use glam::{Vec3, Vec4};

use super::watertight::RayPre;

/// Up to four consecutive triangles (in layout order), one per lane.
#[derive(Clone, Copy, Debug)]
pub(super) struct TriPack {
    /// `corners[c][a]`: coordinate `a` (x, y, z) of corner `c` of each lane's triangle; lanes past
    /// `lanes` repeat the last triangle and are never reported.
    corners: [[Vec4; 3]; 3],
    /// Layout index of lane 0's triangle (lane `l`: `first + l`).
    first: u32,
    /// Lanes in use, 1..=4.
    lanes: u32,
}

impl TriPack {
    /// The packs of the triangles `tris` (layout indices `first ..`), four per pack.
    pub(super) fn pack(tris: &[[Vec3; 3]], first: u32) -> impl Iterator<Item = TriPack> + '_ {
        tris.chunks(4).enumerate().map(move |(k, chunk)| {
            let lane = |l: usize| chunk[l.min(chunk.len() - 1)];
            TriPack {
                corners: std::array::from_fn(|c| {
                    std::array::from_fn(|a| Vec4::from_array(std::array::from_fn(|l| lane(l)[c][a])))
                }),
                first: first + 4 * k as u32,
                lanes: chunk.len() as u32,
            }
        })
    }

    /// Tests the pack's triangles against `pre` one after another in layout order, as a loop of
    /// [`RayPre::intersect`] with the limit `*best_t` would, calling `keep(layout index, t)` for each
    /// hit found; `keep` returns whether the hit becomes the closest (then `*best_t = t`).
    #[inline(always)]
    pub(super) fn intersect(
        &self,
        pre: &RayPre,
        tris: &[[Vec3; 3]],
        best_t: &mut f32,
        mut keep: impl FnMut(u32, f32) -> bool,
    ) {
        let (kx, ky, kz) = (pre.kx, pre.ky, pre.kz);
        let origin = pre.origin.to_array();
        let rel = |c: usize, a: usize| self.corners[c][a] - Vec4::splat(origin[a]);
        let (az, bz, cz) = (rel(0, kz), rel(1, kz), rel(2, kz));
        let (sx, sy, sz) = (Vec4::splat(pre.sx), Vec4::splat(pre.sy), Vec4::splat(pre.sz));
        let ax = rel(0, kx) - sx * az;
        let ay = rel(0, ky) - sy * az;
        let bx = rel(1, kx) - sx * bz;
        let by = rel(1, ky) - sy * bz;
        let cx = rel(2, kx) - sx * cz;
        let cy = rel(2, ky) - sy * cz;
        let u = cx * by - cy * bx;
        let v = ax * cy - ay * cx;
        let w = bx * ay - by * ax;
        let zero = Vec4::ZERO;
        let on_edge = u.cmpeq(zero) | v.cmpeq(zero) | w.cmpeq(zero);
        let outside = (u.cmplt(zero) | v.cmplt(zero) | w.cmplt(zero)) & (u.cmpgt(zero) | v.cmpgt(zero) | w.cmpgt(zero));
        let det = u + v + w;
        let candidate = !outside & det.cmpne(zero);
        let in_use = (1u32 << self.lanes) - 1;
        let on_edge = on_edge.bitmask() & in_use;
        let mut todo = (candidate.bitmask() & in_use) | on_edge;
        if todo == 0 {
            return;
        }
        let t_scaled = u * (sz * az) + v * (sz * bz) + w * (sz * cz);
        let (t_scaled, det) = (t_scaled.to_array(), det.to_array());
        while todo != 0 {
            let l = todo.trailing_zeros();
            todo &= todo - 1;
            let i = self.first + l;
            let t = if on_edge & (1 << l) != 0 {
                let [a, b, c] = tris[i as usize];
                pre.intersect(a, b, c, *best_t)
            } else {
                RayPre::distance(t_scaled[l as usize], det[l as usize], *best_t)
            };
            if let Some(t) = t
                && keep(i, t)
            {
                *best_t = t;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cast::Ray;
    use rand::{RngExt, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    /// Random triangles (some sharing corners, some degenerate) against random rays: every pack
    /// reports the hits of the scalar loop, bit for bit.
    #[test]
    fn pack_matches_the_scalar_loop() {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
        let mut p = |s: f32| Vec3::new(rng.random_range(-s..s), rng.random_range(-s..s), rng.random_range(-s..s));
        let mut tris: Vec<[Vec3; 3]> = (0..600).map(|_| [p(2.0), p(2.0), p(2.0)]).collect();
        // Shared edges and a degenerate (zero-area) triangle.
        for k in (0..600).step_by(7) {
            tris[k + 1][0] = tris[k][1];
            tris[k + 1][1] = tris[k][0];
        }
        tris[10] = [tris[10][0], tris[10][0], tris[10][1]];
        let mut checked = 0;
        for n in 0..3000 {
            let origin = p(4.0);
            let target = tris[n % 600][0] * 0.5 + tris[n % 600][1] * 0.5; // Through an edge.
            let dir = if n % 2 == 0 { (target - origin).normalize() } else { p(1.0).normalize() };
            let pre = RayPre::new(&Ray { origin, dir, t_max: if n % 5 == 0 { 3.0 } else { f32::INFINITY } });
            for first in (0..600).step_by(4).take(150) {
                let count = 1 + (first / 4) % 4;
                let slice = &tris[first..first + count];
                // The leaf loop of `wide.rs` (layout index = mesh index here: a tie keeps the first).
                let mut want: (Option<(usize, u32)>, f32) = (None, pre.t_max);
                for (j, [a, b, c]) in slice.iter().enumerate() {
                    if let Some(t) = pre.intersect(*a, *b, *c, want.1)
                        && (want.0.is_none() || t < want.1)
                    {
                        want = (Some((first + j, t.to_bits())), t);
                    }
                }
                let mut got: Option<(usize, u32)> = None;
                let mut best_t = pre.t_max;
                for pack in TriPack::pack(slice, first as u32) {
                    pack.intersect(&pre, &tris, &mut best_t, |i, t| {
                        let better = got.is_none_or(|(_, bt)| t < f32::from_bits(bt));
                        if better {
                            got = Some((i as usize, t.to_bits()));
                        }
                        better
                    });
                }
                assert_eq!(got, want.0, "ray {n}, leaf at {first}");
                checked += usize::from(want.0.is_some());
            }
        }
        assert!(checked > 1000, "only {checked} hits: the test would not see a difference");
    }
}
