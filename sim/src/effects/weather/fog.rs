//! Fog's own return: the backscatter of the air between the sensor and the target, seen through the
//! laser pulse (Rasshofer, Spies and Spies 2011; the constants of Hahner et al., ICCV 2021, whose
//! LiDAR_fog_sim applies the same equations to finished clouds).
//!
//! The pulse is `P_0 sin^2(pi t / (2 tau_H))` for `0 <= t <= 2 tau_H` (`tau_H = 20 ns`, a 6 m long
//! pulse in range). A soft target of backscatter `beta` in front of a hard target at `R_0` returns,
//! at range `R`,
//!
//! `P_fog(R) = C_A P_0 beta (2/c) int_0^{c tau_H} sin^2(pi s / (c tau_H)) g(R - s) [R - s <= R_0] ds`,
//! with `g(x) = exp(-2 alpha x) xi(x) / x^2` and the overlap `xi` rising linearly from 0 at 0.9 m
//! to 1 at 1.0 m. `I(R_0) = max_R P_fog / (C_A P_0 beta)` and `R_fog` its argmax (about 4.6 m at
//! visibility 50 m) are tabulated per visibility once. As in Hahner et al. the system constant is
//! set by a hard target of constant `beta_0 = Gamma / pi`, `Gamma = 1e-6`: a unit-reflectance
//! target at `r_ref` has power 1 in the intensity model's units, so the fog's return has power
//! `r_ref^2 (beta / beta_0) I(R_0)`. Unlike a post-processing of finished clouds, every beam meets
//! the fog, including beams that return nothing (`R_0` = the maximum range); the fog return's
//! range is drawn from the pulse-weighted backscatter profile around `R_fog`.

use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

use crate::noise::BeamKey;
use crate::scene::SemanticClass;
use crate::sensor::Measurement;

/// Speed of light, m/s.
const C_M_PER_S: f64 = 299_792_458.0;
/// Half-power pulse width, s.
pub const TAU_H_S: f64 = 20e-9;
/// Overlap: zero below, full above (m).
pub const OVERLAP_M: (f64, f64) = (0.9, 1.0);
/// Hahner et al.'s hard-target constant `Gamma` (`beta_0 = Gamma / pi`).
pub const GAMMA: f64 = 1e-6;
/// Backscatter per extinction of fog: `beta = 0.046 / V` against `alpha = ln 20 / V`.
pub const BACKSCATTER_TIMES_VISIBILITY: f64 = 0.046;

/// Extinction of fog of visibility `visibility_m` (Koschmieder, 5 % contrast): `ln 20 / V`.
pub fn extinction_per_m(visibility_m: f64) -> f64 {
    20f64.ln() / visibility_m
}

/// The overlap of beam and receiver at range `x`: 0 below `OVERLAP_M.0`, 1 above `OVERLAP_M.1`.
pub(super) fn overlap(x: f64) -> f64 {
    ((x - OVERLAP_M.0) / (OVERLAP_M.1 - OVERLAP_M.0)).clamp(0.0, 1.0)
}

/// `I(R_0)` and `R_fog(R_0)` for target ranges `0, STEP, 2 STEP, ...`; beyond the last entry (a
/// target farther than the pulse reaches back) they no longer change.
#[derive(Debug)]
pub struct FogTable {
    /// `(I, R_fog)` per target range.
    entries: Vec<(f64, f64)>,
    /// Power of the fog's return per unit `I`: `r_ref^2 beta / beta_0`.
    scale: f64,
    /// The sensor's minimum range (nearer fog returns are not reported).
    min_range_m: f32,
    /// The profile around the peak the fog return's range is drawn from: cumulative weights over
    /// ranges `R_fog - 3 m .. R_fog + 3 m` (of the far-target response).
    profile: Vec<(f64, f64)>,
}

/// Tables built so far, by (visibility bits, intensity reference bits, minimum range bits).
type TableCache = HashMap<(u64, u32, u32), Arc<FogTable>>;

/// Target-range step of the table, m.
const STEP_M: f64 = 0.1;
/// The table's last target range, m: beyond `R_fog + c tau_H` nothing changes.
const LAST_M: f64 = 16.0;

/// The normalised fog response at range `r` to a target at `r0`: `(2/c) int ...` (module docs),
/// in seconds per square metre like Hahner et al.'s tables.
fn response(r: f64, r0: f64, alpha: f64) -> f64 {
    const N: usize = 96;
    let len = C_M_PER_S * TAU_H_S; // 6 m
    let ds = len / N as f64;
    let mut sum = 0.0;
    for k in 0..N {
        let s = (k as f64 + 0.5) * ds;
        let x = r - s;
        if x <= OVERLAP_M.0 || x > r0 {
            continue;
        }
        let w = (std::f64::consts::PI * s / len).sin().powi(2);
        sum += w * (-2.0 * alpha * x).exp() * overlap(x) / (x * x);
    }
    sum * ds * 2.0 / C_M_PER_S
}

/// `(I, R_fog)` for a target at `r0`: the response's maximum over `R` and where it lies (a 0.1 m
/// search, refined to 0.01 m around the best).
fn peak(r0: f64, alpha: f64) -> (f64, f64) {
    let end = r0.min(LAST_M) + C_M_PER_S * TAU_H_S;
    let best_in = |from: f64, to: f64, step: f64, best: (f64, f64)| {
        let mut best = best;
        let mut r = from;
        while r <= to {
            let v = response(r, r0, alpha);
            if v > best.0 {
                best = (v, r);
            }
            r += step;
        }
        best
    };
    let coarse = best_in(OVERLAP_M.0, end, 0.1, (0.0, 0.0));
    if coarse.0 == 0.0 {
        return coarse;
    }
    best_in(coarse.1 - 0.1, coarse.1 + 0.1, 0.01, coarse)
}

impl FogTable {
    /// The table for fog of visibility `visibility_m` and a sensor measuring with `m`.
    pub fn new(visibility_m: f64, m: &Measurement) -> Self {
        let alpha = extinction_per_m(visibility_m);
        let beta = BACKSCATTER_TIMES_VISIBILITY / visibility_m;
        let beta_0 = GAMMA / std::f64::consts::PI;
        let entries: Vec<(f64, f64)> =
            (0..=(LAST_M / STEP_M) as usize).map(|k| peak(k as f64 * STEP_M, alpha)).collect();
        let far = entries.last().copied().unwrap_or((0.0, 0.0));
        // The far-target response around its peak, as cumulative weights.
        let mut profile = Vec::new();
        let mut acc = 0.0;
        let mut r = (far.1 - 3.0).max(OVERLAP_M.0);
        while r <= far.1 + 3.0 {
            acc += response(r, f64::INFINITY, alpha);
            profile.push((r, acc));
            r += 0.05;
        }
        let r_ref = f64::from(m.intensity_reference_m);
        Self { entries, scale: r_ref * r_ref * beta / beta_0, min_range_m: m.min_range_m, profile }
    }

    /// The table for `visibility_m` and `m`, built once per process and shared.
    pub fn cached(visibility_m: f64, m: &Measurement) -> Arc<Self> {
        static CACHE: OnceLock<Mutex<TableCache>> = OnceLock::new();
        let key = (visibility_m.to_bits(), m.intensity_reference_m.to_bits(), m.min_range_m.to_bits());
        let mut cache = CACHE.get_or_init(Default::default).lock().unwrap_or_else(|e| e.into_inner());
        Arc::clone(cache.entry(key).or_insert_with(|| Arc::new(Self::new(visibility_m, m))))
    }

    /// `(I, R_fog)` for a target at `r0_m` (nearest tabulated range at or below).
    pub fn at(&self, r0_m: f32) -> (f64, f64) {
        let k = ((f64::from(r0_m) / STEP_M) as usize).min(self.entries.len() - 1);
        self.entries[k]
    }

    /// The power of the fog's return in front of a target at `r0_m`.
    pub fn power(&self, r0_m: f32) -> f32 {
        (self.scale * self.at(r0_m).0) as f32
    }

    /// The fog's return in a beam whose target lies at `reach_m` (or the maximum range), when it
    /// is at least `floor` strong: `(range, power, class)`.
    pub(super) fn strongest(&self, reach_m: f32, floor: f32, key: &BeamKey) -> Option<(f32, f32, SemanticClass)> {
        let power = self.power(reach_m);
        if power < floor {
            return None;
        }
        let (_, r_fog) = self.at(reach_m);
        // A far target's return is drawn from the backscatter profile; a near one sits at its peak.
        let range = if reach_m as f64 > LAST_M {
            let u = f64::from(super::uniforms(key).next().unwrap_or(0.5));
            let total = self.profile.last().map_or(1.0, |p| p.1);
            self.profile.iter().find(|p| p.1 >= u * total).map_or(r_fog, |p| p.0)
        } else {
            r_fog
        } as f32;
        (range >= self.min_range_m && range < reach_m).then_some((range, power, SemanticClass::FOG))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hdl() -> Measurement {
        crate::Rig::load("hdl64e-roof").unwrap().sensors[0].spec.measurement()
    }

    /// Hahner et al.'s lookup tables (LiDAR_fog_sim, `integral_lookup_tables/original`, read by
    /// their code for far targets): at alpha 0.06 the peak is 3.82e-9 at 4.60 m, at alpha 0.02
    /// 4.35e-9 at 4.70 m.
    #[test]
    fn the_integral_matches_the_published_tables() {
        for (visibility, i, r) in [(20f64.ln() / 0.06, 3.82e-9, 4.60), (20f64.ln() / 0.02, 4.35e-9, 4.70)] {
            let t = FogTable::new(visibility, &hdl());
            let (got_i, got_r) = t.at(100.0);
            assert!((got_i / i - 1.0).abs() < 0.03, "V {visibility}: I {got_i:e} vs {i:e}");
            assert!((got_r - r).abs() < 0.1, "V {visibility}: R_fog {got_r} vs {r}");
        }
    }

    #[test]
    fn near_targets_leave_less_fog_in_front_of_them() {
        let t = FogTable::new(50.0, &hdl());
        assert_eq!(t.power(0.5), 0.0, "no fog before the overlap");
        // The fog in front of a target can only grow with the target's range.
        let powers: Vec<f32> = (0..160).map(|k| t.power(k as f32 * 0.1)).collect();
        assert!(powers.windows(2).all(|w| w[0] <= w[1]), "{powers:?}");
        assert!(t.power(1.2) < 0.5 * t.power(30.0), "{} vs {}", t.power(1.2), t.power(30.0));
        assert_eq!(t.power(30.0), t.power(120.0), "beyond the pulse's reach the return no longer changes");
    }
}
