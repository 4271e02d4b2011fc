//! The model's trees laid out for evaluation: every tree's levels and leaves in flat arrays, and
//! the margins of many cells computed [`LANES`] cells at a time from feature-major columns (an
//! oblivious tree's level asks the same question of every cell, so a level is one comparison of a
//! contiguous run of feature values against one threshold, which the compiler vectorizes).

use super::model::LearnedModel;

/// Cells evaluated together.
pub const LANES: usize = 16;

/// Depth of the tables of the AVX-512 path: 64 leaves, four registers.
const TABLE_DEPTH: usize = 6;

/// The trees of a model, flat, every tree padded to the model's deepest (a padded level asks
/// "feature 0 at least +inf?", which no finite feature is: answer 0, and each leaf is repeated
/// under it), so that the evaluation loop knows the depth and the leaf count at compile time.
#[derive(Clone, Debug, Default)]
pub struct Forest {
    /// The common depth.
    depth: usize,
    /// (feature, threshold) per level, `depth` per tree.
    levels: Vec<(u8, f32)>,
    /// `2^depth` leaves per tree.
    leaves: Vec<f32>,
    /// The trees padded to depth [`TABLE_DEPTH`] (where none is deeper): levels and 64-leaf tables.
    table_levels: Vec<(u8, f32)>,
    tables: Vec<[f32; 1 << TABLE_DEPTH]>,
    base_margin: f32,
}

impl Forest {
    /// The forest of `model` (checked by [`LearnedModel::check`]).
    pub fn new(model: &LearnedModel) -> Self {
        let depth = model.trees.iter().map(|t| t.depth()).max().unwrap_or(1);
        let mut f = Forest { depth, base_margin: model.base_margin, ..Forest::default() };
        let padded =
            |t: &super::model::ObliviousTree, to: usize, levels: &mut Vec<(u8, f32)>, leaves: &mut Vec<f32>| {
                let pad = to - t.depth();
                levels.extend(t.features.iter().zip(&t.thresholds).map(|(&a, &b)| (a, b)));
                levels.extend(std::iter::repeat_n((0u8, f32::INFINITY), pad));
                for &leaf in &t.leaves {
                    leaves.extend(std::iter::repeat_n(leaf, 1 << pad));
                }
            };
        for t in &model.trees {
            padded(t, depth, &mut f.levels, &mut f.leaves);
        }
        if depth <= TABLE_DEPTH {
            let mut leaves = Vec::new();
            for t in &model.trees {
                padded(t, TABLE_DEPTH, &mut f.table_levels, &mut leaves);
            }
            f.tables = leaves.chunks_exact(1 << TABLE_DEPTH).map(|c| c.try_into().expect("64 leaves")).collect();
        }
        f
    }

    /// The margins of `count` cells whose feature `k` is `columns[k][j]`, `j < count`; each column
    /// holds at least `count` rounded up to a multiple of [`LANES`] values (the padding is read and
    /// its margins dropped). Writes `out[..count]`. Runs as code compiled for AVX-512 or AVX2 where
    /// the CPU has it (the same bits: compares and additions in the same order).
    pub fn margins(&self, columns: &[Vec<f32>], count: usize, out: &mut [f32]) {
        #[cfg(target_arch = "x86_64")]
        if crate::cpu::avx512() {
            // SAFETY: the CPU supports AVX-512 F, BW, VL and DQ, AVX2, BMI1 and BMI2 (checked just above).
            #[allow(unsafe_code)]
            unsafe {
                return self.margins_avx512(columns, count, out);
            }
        }
        #[cfg(target_arch = "x86_64")]
        if crate::cpu::avx2_bmi() {
            // SAFETY: the CPU supports AVX2, BMI1 and BMI2 (checked just above).
            #[allow(unsafe_code)]
            unsafe {
                return self.margins_avx2(columns, count, out);
            }
        }
        self.margins_any(columns, count, out);
    }

    /// The margins with AVX-512 (the same bits as [`Forest::margins_any`]: the same compares,
    /// the leaves added in the same order). For trees of depth 6 or less the leaves are looked up
    /// by permutes of 64-leaf tables held in four registers (every tree padded to depth 6), not by
    /// gathers (a gather costs more than the tree's six comparisons); deeper forests take
    /// [`Forest::margins_any`]. Four 16-cell chunks go through each tree together (64 cells, then
    /// the rest one chunk at a time): each tree's table and thresholds are loaded once for them, and
    /// four independent chains of compares, permutes and sums keep the core busy where one chain
    /// waited on its own sum (a KITTI frame's trees 2.9 -> 1.4 ms on one core).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512bw,avx512vl,avx512dq,avx2,bmi1,bmi2")]
    fn margins_avx512(&self, columns: &[Vec<f32>], count: usize, out: &mut [f32]) {
        if self.depth > TABLE_DEPTH {
            return self.margins_any(columns, count, out);
        }
        let chunks = count.div_ceil(LANES);
        let wide = chunks / 4 * 4;
        for ch in (0..wide).step_by(4) {
            self.margins_avx512_chunks::<4>(columns, ch * LANES, count, out);
        }
        for ch in wide..chunks {
            self.margins_avx512_chunks::<1>(columns, ch * LANES, count, out);
        }
    }

    /// The margins of the `16 V` cells from `start` (columns padded past them), written to
    /// `out[start..count.min(start + 16 V)]`.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512bw,avx512vl,avx512dq,avx2,bmi1,bmi2")]
    fn margins_avx512_chunks<const V: usize>(&self, columns: &[Vec<f32>], start: usize, count: usize, out: &mut [f32]) {
        use std::arch::x86_64::*;
        let one = _mm512_set1_epi32(1);
        let bit5 = _mm512_set1_epi32(32);
        let mut acc = [_mm512_set1_ps(self.base_margin); V];
        for (levels, table) in self.table_levels.chunks_exact(TABLE_DEPTH).zip(&self.tables) {
            let mut idx = [_mm512_setzero_si512(); V];
            for &(f, t) in levels {
                let col = &columns[f as usize][start..start + LANES * V];
                let t = _mm512_set1_ps(t);
                for v in 0..V {
                    let x: [f32; LANES] = col[LANES * v..LANES * (v + 1)].try_into().expect("padded");
                    let ge = _mm512_cmp_ps_mask::<_CMP_GE_OQ>(bytemuck::cast(x), t);
                    idx[v] = _mm512_add_epi32(idx[v], idx[v]);
                    idx[v] = _mm512_mask_add_epi32(idx[v], ge, idx[v], one);
                }
            }
            let [t0, t1, t2, t3]: [__m512; 4] = bytemuck::cast(*table);
            for v in 0..V {
                let low = _mm512_permutex2var_ps(t0, idx[v], t1);
                let high = _mm512_permutex2var_ps(t2, idx[v], t3);
                let upper_half = _mm512_test_epi32_mask(idx[v], bit5);
                acc[v] = _mm512_add_ps(acc[v], _mm512_mask_blend_ps(upper_half, low, high));
            }
        }
        for (v, a) in acc.iter().enumerate() {
            let from = start + LANES * v;
            if from >= count {
                break;
            }
            let a: [f32; LANES] = bytemuck::cast(*a);
            let n = LANES.min(count - from);
            out[from..from + n].copy_from_slice(&a[..n]);
        }
    }

    /// The margins with AVX2 (the same bits as [`Forest::margins_any`]: the same compares, the
    /// leaves added in the same order). For trees of depth 6 or less, 32 cells at a time (16 for
    /// the last chunk), eight per register: the last three levels' answers index eight permutes of
    /// the 64-leaf table's eighths, and the first three levels' compare masks pick among them by
    /// blends (cheaper than a gather on the AMD cores measured); deeper forests take
    /// [`Forest::margins_any`].
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,bmi1,bmi2")]
    fn margins_avx2(&self, columns: &[Vec<f32>], count: usize, out: &mut [f32]) {
        if self.depth > TABLE_DEPTH {
            return self.margins_any(columns, count, out);
        }
        let padded = count.div_ceil(LANES) * LANES;
        let column_starts: Vec<&[f32]> = columns.iter().map(|c| &c[..padded]).collect();
        let wide = padded / (4 * 8) * (4 * 8);
        for start in (0..wide).step_by(4 * 8) {
            self.margins_avx2_chunk::<4>(&column_starts, start, count, out);
        }
        if wide < padded {
            self.margins_avx2_chunk::<2>(&column_starts, wide, count, out);
        }
    }

    /// The margins of the `8 V` cells from `start` (columns padded past them), written to
    /// `out[start..count.min(start + 8 V)]`.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,bmi1,bmi2")]
    fn margins_avx2_chunk<const V: usize>(&self, columns: &[&[f32]], start: usize, count: usize, out: &mut [f32]) {
        use std::arch::x86_64::*;
        let mut acc = [_mm256_set1_ps(self.base_margin); V];
        for (levels, table) in self.table_levels.chunks_exact(TABLE_DEPTH).zip(&self.tables) {
            // The first three levels' masks (leaf index bits 5, 4, 3) and the last three levels'
            // answers as an index 0..8 (bits 2, 1, 0).
            let mut high = [[_mm256_setzero_ps(); V]; 3];
            let mut low = [_mm256_setzero_si256(); V];
            for (l, &(f, t)) in levels.iter().enumerate() {
                let col = &columns[f as usize][start..start + 8 * V];
                let t = _mm256_set1_ps(t);
                for v in 0..V {
                    let x: [f32; 8] = col[8 * v..8 * v + 8].try_into().expect("8 lanes");
                    let ge = _mm256_cmp_ps::<_CMP_GE_OQ>(bytemuck::cast(x), t);
                    if l < 3 {
                        high[l][v] = ge;
                    } else {
                        // All ones where at least t: minus -1 adds the bit.
                        low[v] = _mm256_sub_epi32(_mm256_add_epi32(low[v], low[v]), _mm256_castps_si256(ge));
                    }
                }
            }
            let eighths: [__m256; 8] = bytemuck::cast(*table);
            for v in 0..V {
                let e: [__m256; 8] = std::array::from_fn(|q| _mm256_permutevar8x32_ps(eighths[q], low[v]));
                let [b5, b4, b3] = [high[0][v], high[1][v], high[2][v]];
                let quarters = [
                    _mm256_blendv_ps(e[0], e[1], b3),
                    _mm256_blendv_ps(e[2], e[3], b3),
                    _mm256_blendv_ps(e[4], e[5], b3),
                    _mm256_blendv_ps(e[6], e[7], b3),
                ];
                let halves =
                    [_mm256_blendv_ps(quarters[0], quarters[1], b4), _mm256_blendv_ps(quarters[2], quarters[3], b4)];
                acc[v] = _mm256_add_ps(acc[v], _mm256_blendv_ps(halves[0], halves[1], b5));
            }
        }
        for (v, a) in acc.iter().enumerate() {
            let from = start + 8 * v;
            if from >= count {
                break;
            }
            let a: [f32; 8] = bytemuck::cast(*a);
            let n = 8.min(count - from);
            out[from..from + n].copy_from_slice(&a[..n]);
        }
    }

    /// The depth's own loop.
    #[inline(always)]
    fn margins_any(&self, columns: &[Vec<f32>], count: usize, out: &mut [f32]) {
        match self.depth {
            1 => self.margins_body::<1, 2>(columns, count, out),
            2 => self.margins_body::<2, 4>(columns, count, out),
            3 => self.margins_body::<3, 8>(columns, count, out),
            4 => self.margins_body::<4, 16>(columns, count, out),
            5 => self.margins_body::<5, 32>(columns, count, out),
            6 => self.margins_body::<6, 64>(columns, count, out),
            7 => self.margins_body::<7, 128>(columns, count, out),
            8 => self.margins_body::<8, 256>(columns, count, out),
            9 => self.margins_body::<9, 512>(columns, count, out),
            _ => self.margins_body::<10, 1024>(columns, count, out),
        }
    }

    /// The loop over chunks of [`LANES`] cells and the trees, for trees of depth `D` (`L` = 2^D
    /// leaves).
    #[inline(always)]
    fn margins_body<const D: usize, const L: usize>(&self, columns: &[Vec<f32>], count: usize, out: &mut [f32]) {
        let chunks = count.div_ceil(LANES);
        for ch in 0..chunks {
            let start = ch * LANES;
            let mut acc = [self.base_margin; LANES];
            for (levels, leaves) in self.levels.chunks_exact(D).zip(self.leaves.chunks_exact(L)) {
                let leaves: &[f32; L] = leaves.try_into().expect("L leaves");
                let mut idx = [0u32; LANES];
                for &(f, t) in levels {
                    let col: &[f32; LANES] = columns[f as usize][start..start + LANES].try_into().expect("padded");
                    for l in 0..LANES {
                        idx[l] = 2 * idx[l] + u32::from(col[l] >= t);
                    }
                }
                for l in 0..LANES {
                    acc[l] += leaves[idx[l] as usize & (L - 1)];
                }
            }
            let n = LANES.min(count - start);
            out[start..start + n].copy_from_slice(&acc[..n]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::learned::features::FEATURE_COUNT;
    use crate::learned::model::ObliviousTree;
    use rand::{RngExt, SeedableRng};

    #[test]
    fn lanes_give_the_models_own_margins() {
        // Trees up to depth 6 (the AVX-512 and AVX2 tables) and up to 9 (the other loop); cell
        // counts below one chunk, with a 16-cell tail after 32-cell chunks, a whole number of
        // chunks, and 64-cell groups with single chunks and a short one after them.
        for max_depth in [6, 9] {
            for count in [5, 37, 64, 200] {
                margins_agree(max_depth, count);
            }
        }
    }

    fn margins_agree(max_depth: usize, count: usize) {
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(3);
        let trees: Vec<ObliviousTree> = (0..40)
            .map(|k| {
                let d = 1 + k % max_depth;
                ObliviousTree {
                    features: (0..d).map(|_| rng.random_range(0..FEATURE_COUNT as u8)).collect(),
                    thresholds: (0..d).map(|_| rng.random::<f32>()).collect(),
                    leaves: (0..1 << d).map(|_| rng.random::<f32>() - 0.5).collect(),
                }
            })
            .collect();
        let model = LearnedModel::new(0.25, 0.5, trees);
        let forest = Forest::new(&model);
        let padded = count.div_ceil(LANES) * LANES;
        let columns: Vec<Vec<f32>> =
            (0..FEATURE_COUNT).map(|_| (0..padded).map(|_| rng.random::<f32>()).collect()).collect();
        let (mut out, mut portable) = (vec![0.0; count], vec![0.0; count]);
        forest.margins(&columns, count, &mut out);
        forest.margins_any(&columns, count, &mut portable);
        for j in 0..count {
            let x: [f32; FEATURE_COUNT] = std::array::from_fn(|k| columns[k][j]);
            assert_eq!(out[j], model.margin(&x), "cell {j} of {count}, depth up to {max_depth}");
            assert_eq!(portable[j], out[j], "cell {j} of {count}, depth up to {max_depth}");
        }
    }
}
