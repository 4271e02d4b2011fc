//! The cluster rules of Nitsch et al. (module docs of [`super`]): each cluster's decision from its
//! size, its height against the ground area around the sensor and the mean height of the area's
//! points near it, written to every cell of the plane.

use glam::Vec3;

use super::{ClusterParams, ClusterWorkspace, NONE};

/// A count of [`ClusterWorkspace`]'s `near` squares not computed yet.
const NOT_YET: u32 = u32::MAX;

/// The mean height of the ground-area points in the 3 x 3 squares around square `(x, y)` of the
/// `nx` x `ny` area (sums of height and count per square), and their count (mean 0 without any).
#[inline]
fn near_mean(area: &[(f32, u32)], nx: usize, ny: usize, x: isize, y: isize) -> (f32, u32) {
    let (mut zs, mut cnt) = (0.0f32, 0u32);
    for dy in -1..=1 {
        for dx in -1..=1 {
            let (xx, yy) = (x + dx, y + dy);
            if xx >= 0 && yy >= 0 && (xx as usize) < nx && (yy as usize) < ny {
                let e = area[yy as usize * nx + xx as usize];
                zs += e.0;
                cnt += e.1;
            }
        }
    }
    (if cnt > 0 { zs / cnt as f32 } else { 0.0 }, cnt)
}

/// `v.floor() as isize`, bit for bit (saturating, NaN to 0), without a call to `floorf` (the
/// baseline x86-64 target has no rounding instruction): truncation toward zero, one less where
/// that rounded a negative value up (a subtraction, not a branch: points on either side of the
/// area's corner would mispredict it).
#[inline]
pub(super) fn floor_isize(v: f32) -> isize {
    let t = v as isize;
    if (t as f32) > v { t.saturating_sub(1) } else { t }
}

impl ClusterWorkspace {
    /// Applies the cluster rules (module docs) and writes the ground decision of every cell of the
    /// plane into `ground` (non-candidates false). `points` are the points of the last
    /// [`super::cluster_candidates`] (whose pass also found each cluster's bounding box) and `returns` the
    /// number of returns of the plane. (Compiled for AVX-512 or AVX2 and BMI where the CPU has them, as
    /// [`super::cluster_candidates_with`].)
    pub fn decide(&mut self, points: &[Vec3], returns: usize, params: &ClusterParams, ground: &mut [bool]) {
        #[cfg(target_arch = "x86_64")]
        if crate::cpu::avx512() {
            // SAFETY: the CPU supports AVX-512 F, BW, VL and DQ, AVX2, BMI1 and BMI2 (checked just above).
            #[allow(unsafe_code)]
            unsafe {
                return self.decide_avx512(points, returns, params, ground);
            }
        }
        #[cfg(target_arch = "x86_64")]
        if crate::cpu::avx2_bmi() {
            // SAFETY: the CPU supports AVX2, BMI1 and BMI2 (checked just above).
            #[allow(unsafe_code)]
            unsafe {
                return self.decide_avx2(points, returns, params, ground);
            }
        }
        self.decide_body(points, returns, params, ground);
    }

    /// [`ClusterWorkspace::decide_body`] compiled for AVX2, BMI1 and BMI2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,bmi1,bmi2")]
    fn decide_avx2(&mut self, points: &[Vec3], returns: usize, params: &ClusterParams, ground: &mut [bool]) {
        self.decide_body(points, returns, params, ground);
    }

    /// [`ClusterWorkspace::decide_body`] compiled for AVX-512 ([`crate::cpu::avx512`]).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512bw,avx512vl,avx512dq,avx2,bmi1,bmi2")]
    fn decide_avx512(&mut self, points: &[Vec3], returns: usize, params: &ClusterParams, ground: &mut [bool]) {
        self.decide_body(points, returns, params, ground);
    }

    /// The body of [`ClusterWorkspace::decide`], inlined into each instruction-set variant.
    #[inline(always)]
    pub(super) fn decide_body(&mut self, points: &[Vec3], returns: usize, params: &ClusterParams, ground: &mut [bool]) {
        let n = self.parent.len();
        // Every candidate's parent is its root already ([`cluster_candidates`] compresses the paths).
        let size = &self.size;
        let Some(largest) = self.roots.iter().map(|&r| r as usize).max_by_key(|&r| (size[r], std::cmp::Reverse(r)))
        else {
            ground[..n].fill(false);
            return;
        };
        // Ground area: squares holding points of the largest cluster, over its bounding box.
        let cell = params.area_cell_m;
        let (lo, hi) = self.bbox[largest];
        let nx = (((hi.x - lo.x) / cell).floor() as usize).saturating_add(1).min(4096);
        let ny = (((hi.y - lo.y) / cell).floor() as usize).saturating_add(1).min(4096);
        self.area.clear();
        self.area.resize(nx * ny, (0.0, 0));
        // A multiplication rather than a division per coordinate (exactly the quotient for the
        // default 2 m squares, and for any power of two).
        let per_cell = 1.0 / cell;
        let square = |p: Vec3| -> (isize, isize) {
            (floor_isize((p.x - lo.x) * per_cell), floor_isize((p.y - lo.y) * per_cell))
        };
        // Consecutive points mostly fall in one square: its sums stay in registers for the run
        // (the same additions in the same order, without a chain through memory per point).
        let (parent, area) = (&self.parent[..], &mut self.area[..]);
        let (mut run, mut acc) = (usize::MAX, (0f32, 0u32));
        // The members of the other clusters, for the area test below (most members are the
        // largest cluster's: that loop then skips none).
        self.others.clear();
        for &i in &self.members {
            if parent[i as usize] != largest as u32 {
                self.others.push(i);
            } else {
                let p = points[i as usize];
                // The largest cluster's points lie inside its box: `p - lo >= 0`, whose truncation
                // is its floor (one conversion, no correction; `nx`, `ny` <= 4096).
                let x = (((p.x - lo.x) * per_cell) as i32).clamp(0, nx as i32 - 1) as usize;
                let y = (((p.y - lo.y) * per_cell) as i32).clamp(0, ny as i32 - 1) as usize;
                let k = y * nx + x;
                if k != run {
                    if run != usize::MAX {
                        area[run] = acc;
                    }
                    (run, acc) = (k, area[k]);
                }
                acc = (acc.0 + p.z, acc.1 + 1);
            }
        }
        if run != usize::MAX {
            area[run] = acc;
        }
        // Area test per cluster: count inside points and their height above the local ground.
        // Per-root arrays: sized once, reset at the roots only (they are read nowhere else).
        self.inside.resize(n, 0);
        self.height_sum.resize(n, 0.0);
        self.outside_sum.resize(n, Vec3::ZERO);
        self.root_ground.resize(n, false);
        for &root in &self.roots {
            let r = root as usize;
            (self.inside[r], self.height_sum[r], self.outside_sum[r]) = (0, 0.0, Vec3::ZERO);
            self.root_ground[r] = false;
        }
        // The 3 x 3 sums around a square are found once per square, when a point first needs
        // them (most points of a cluster share squares), not once per point.
        let wx = nx + 2;
        self.near.clear();
        self.near.resize(wx * (ny + 2), (0.0, NOT_YET));
        // Consecutive members mostly share a root: its sums stay in registers for the run.
        // A cluster whose box lies beyond the area's border has all its points outside: those
        // only add up (most of the terrain beside a road on `rural`).
        let beyond = |(lo, hi): (glam::Vec2, glam::Vec2)| {
            let ((x0, y0), (x1, y1)) = (square(lo.extend(0.0)), square(hi.extend(0.0)));
            x1 < -1 || y1 < -1 || x0 > nx as isize || y0 > ny as isize
        };
        let (mut run, mut far, mut inside, mut height, mut outside) = (NONE, false, 0u32, 0f32, Vec3::ZERO);
        for &i in &self.others {
            let root = self.parent[i as usize];
            if (self.size[root as usize] as usize) < params.min_cluster_points {
                continue;
            }
            if root != run {
                if run != NONE {
                    let r = run as usize;
                    (self.inside[r], self.height_sum[r], self.outside_sum[r]) = (inside, height, outside);
                }
                run = root;
                let r = root as usize;
                (inside, height, outside) = (self.inside[r], self.height_sum[r], self.outside_sum[r]);
                far = beyond(self.bbox[r]);
            }
            let p = points[i as usize];
            if far {
                outside += p;
                continue;
            }
            let (x, y) = square(p);
            // Squares beyond the border have no area square around them.
            let (mean, cnt) = if (-1..=nx as isize).contains(&x) && (-1..=ny as isize).contains(&y) {
                let k = (y + 1) as usize * wx + (x + 1) as usize;
                if self.near[k].1 == NOT_YET {
                    self.near[k] = near_mean(&self.area, nx, ny, x, y);
                }
                self.near[k]
            } else {
                (0.0, 0)
            };
            if cnt > 0 {
                inside += 1;
                height += p.z - mean;
            } else {
                outside += p;
            }
        }
        if run != NONE {
            let r = run as usize;
            (self.inside[r], self.height_sum[r], self.outside_sum[r]) = (inside, height, outside);
        }
        let (zsum, zcount) = self.area.iter().fold((0f64, 0u64), |(a, b), e| (a + f64::from(e.0), b + u64::from(e.1)));
        let ground_mean_z = (zsum / zcount.max(1) as f64) as f32;
        let min_large = params.min_large_points.max((params.min_large_fraction * returns as f32).ceil() as usize);
        for ri in 0..self.roots.len() {
            let root = self.roots[ri] as usize;
            let size = self.size[root] as usize;
            self.root_ground[root] = if root == largest {
                true
            } else if size < params.min_cluster_points {
                false
            } else if 10 * self.inside[root] as usize >= size && self.inside[root] as usize >= params.min_cluster_points
            {
                self.height_sum[root] / (self.inside[root] as f32) <= params.max_step_m
            } else if size >= min_large
                || (params.min_large_extent_m > 0.0
                    && (self.bbox[root].1 - self.bbox[root].0).length() >= params.min_large_extent_m
                    && self.outside_sum[root].z / (size - self.inside[root] as usize).max(1) as f32
                        <= ground_mean_z + params.max_step_m)
            {
                true
            } else {
                // Rule 5: level with or below the nearest ground-area square.
                let outside = size - self.inside[root] as usize;
                let c = self.outside_sum[root] / outside.max(1) as f32;
                let (cx, cy) = square(c);
                let reach = (params.near_search_m / cell).ceil() as isize;
                let mut best: Option<(isize, f32)> = None;
                for y in (cy - reach).max(0)..=(cy + reach).min(ny as isize - 1) {
                    for x in (cx - reach).max(0)..=(cx + reach).min(nx as isize - 1) {
                        let e = self.area[y as usize * nx + x as usize];
                        let d2 = (x - cx).pow(2) + (y - cy).pow(2);
                        if e.1 > 0 && d2 <= reach * reach && best.is_none_or(|(bd, _)| d2 < bd) {
                            best = Some((d2, e.0 / e.1 as f32));
                        }
                    }
                }
                best.is_some_and(|(_, z)| c.z - z <= params.max_step_m)
            };
        }
        // Members are the cells with a return and a cluster; every other cell is not ground.
        ground[..n].fill(false);
        for &i in &self.members {
            ground[i as usize] = self.root_ground[self.parent[i as usize] as usize];
        }
    }
}
