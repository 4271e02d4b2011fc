//! Rain drops and snowflakes in the beam: drawn per beam from their size distributions, each
//! returning the share of the beam it covers.
//!
//! - **Sizes**: exponential, `N(D) = N_0 exp(-Lambda D)` per m^3 per mm. Rain: Marshall-Palmer,
//!   `N_0 = 8000`, `Lambda = 4.1 R^-0.21` (R in mm/h), drops up to 6 mm. Snow: Gunn-Marshall in
//!   melted diameters, `N_0 = 3800 R^-0.87`, `Lambda = 2.55 R^-0.48`, flakes of density 0.1 g/cm^3
//!   (diameter `10^(1/3) = 2.15` times the melted one, as in Hahner et al., CVPR 2022), up to 20 mm.
//! - **Extinction** from the same distribution, geometric optics (extinction efficiency 2):
//!   `alpha = (pi / 2) int D^2 N(D) dD = pi N_0 / Lambda^3` (with D in metres): 1.6e-3 /m in rain of
//!   10 mm/h, 5e-3 /m in snow of 2 mm/h.
//! - **A particle's return**: a Lambertian disk of reflectance `rho_p` (snow 0.9, as Hahner et al.;
//!   rain 0.05: clear water returns little to the sensor) covering `min(1, (D / d(R))^2)` of the
//!   beam, whose diameter grows as `d(R) = d_0 + theta R` (`d_0` = 1 cm exit aperture, `theta` the
//!   sensor's divergence): power `rho_p min(1, (D / d)^2) (r_ref / R)^2 xi(R) exp(-2 alpha R)`.
//! - **Per beam**: the particles that could beat the beam's floor (the threshold, or the target's
//!   power when it is stronger) form a Poisson process along the beam, of rate
//!   `A(R) int_{D_min(R)} N(D) dD` per metre (`A` the beam's cross-section). A table holds its
//!   cumulative rate for floors on a factor-sqrt(2) ladder, so a beam draws only the few particles
//!   that can matter (thinning keeps it exact), and the strongest one that beats the floor is the
//!   medium's return.

use rand::RngExt;

use crate::noise::{BeamKey, Purpose};
use crate::scene::SemanticClass;
use crate::sensor::Measurement;

/// A population of particles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Particles {
    /// Intercept of the size distribution, per m^3 per mm (of the particle's own diameter).
    pub n0_per_m3_mm: f64,
    /// Slope of the size distribution, 1/mm.
    pub lambda_per_mm: f64,
    /// Largest diameter, mm.
    pub d_max_mm: f64,
    /// Reflectance of a particle.
    pub reflectance: f64,
    /// The class of its returns.
    pub class: SemanticClass,
}

/// Flake diameter per melted diameter at a snow density of 0.1 g/cm^3: `10^(1/3)`.
const FLAKE_PER_MELTED: f64 = 2.154_434_690_031_884;
/// The beam's diameter at the exit aperture, m.
pub const APERTURE_M: f64 = 0.01;

impl Particles {
    /// Rain of `rate_mm_h` (Marshall-Palmer).
    pub fn rain(rate_mm_h: f64) -> Self {
        let r = rate_mm_h.max(1e-6);
        Self {
            n0_per_m3_mm: if rate_mm_h > 0.0 { 8000.0 } else { 0.0 },
            lambda_per_mm: 4.1 * r.powf(-0.21),
            d_max_mm: 6.0,
            reflectance: 0.05,
            class: SemanticClass::RAIN,
        }
    }

    /// Snow of `rate_mm_h` of water (Gunn-Marshall, flakes of density 0.1 g/cm^3).
    pub fn snow(rate_mm_h: f64) -> Self {
        let r = rate_mm_h.max(1e-6);
        let (n0, lambda) = (3800.0 * r.powf(-0.87), 2.55 * r.powf(-0.48));
        Self {
            n0_per_m3_mm: if rate_mm_h > 0.0 { n0 / FLAKE_PER_MELTED } else { 0.0 },
            lambda_per_mm: lambda / FLAKE_PER_MELTED,
            d_max_mm: 20.0,
            reflectance: 0.9,
            class: SemanticClass::SNOW,
        }
    }

    /// Particles per m^3 with a diameter of at least `d_mm`.
    pub fn count_above(&self, d_mm: f64) -> f64 {
        if d_mm >= self.d_max_mm {
            return 0.0;
        }
        let l = self.lambda_per_mm;
        self.n0_per_m3_mm / l * ((-l * d_mm.max(0.0)).exp() - (-l * self.d_max_mm).exp())
    }

    /// Extinction coefficient, 1/m: `(pi / 2) int D^2 N(D) dD` (the untruncated tail is
    /// negligible).
    pub fn extinction_per_m(&self) -> f64 {
        std::f64::consts::PI * self.n0_per_m3_mm / self.lambda_per_mm.powi(3) * 1e-6
    }
}

/// Floors on the ladder, from the detection threshold up by factors of sqrt(2).
const LEVELS: usize = 48;
/// Range step of the table, m.
const STEP_M: f64 = 0.25;

/// The cumulative rate of particles that could beat each floor, per sensor.
#[derive(Debug)]
pub struct ParticleTable {
    particles: Particles,
    p_min: f64,
    r_ref: f64,
    alpha: f64,
    divergence_rad: f64,
    min_range_m: f64,
    max_range_m: f64,
    /// `cumulative[level][k]`: expected particles in `[min_range, min_range + k STEP)` that could
    /// beat floor `level`.
    cumulative: Vec<Vec<f64>>,
}

impl ParticleTable {
    /// The table for `particles` and a sensor measuring with `m`.
    pub fn new(particles: &Particles, m: &Measurement) -> Self {
        let mut t = Self {
            particles: *particles,
            p_min: f64::from(super::detection_threshold(m)),
            r_ref: f64::from(m.intensity_reference_m),
            alpha: particles.extinction_per_m(),
            divergence_rad: f64::from(m.beam_divergence_rad),
            min_range_m: f64::from(m.min_range_m).max(super::fog::OVERLAP_M.0),
            max_range_m: f64::from(m.max_range_m),
            cumulative: Vec::new(),
        };
        let steps = ((t.max_range_m - t.min_range_m) / STEP_M).ceil().max(1.0) as usize;
        t.cumulative = (0..LEVELS)
            .map(|level| {
                let floor = t.level_floor(level);
                let mut acc = vec![0.0; steps + 1];
                for k in 0..steps {
                    let r = t.min_range_m + (k as f64 + 0.5) * STEP_M;
                    acc[k + 1] = acc[k] + t.rate(r, floor) * STEP_M;
                }
                acc
            })
            .collect();
        t
    }

    fn level_floor(&self, level: usize) -> f64 {
        self.p_min * 2f64.powf(level as f64 / 2.0)
    }

    /// Beam diameter at `r`, m.
    fn beam_m(&self, r: f64) -> f64 {
        APERTURE_M + self.divergence_rad * r
    }

    /// Power of a whole-beam return at `r` (a particle covering the beam).
    fn full_power(&self, r: f64) -> f64 {
        let xi = ((r - super::fog::OVERLAP_M.0) / (super::fog::OVERLAP_M.1 - super::fog::OVERLAP_M.0)).clamp(0.0, 1.0);
        self.particles.reflectance * (self.r_ref / r).powi(2) * xi * (-2.0 * self.alpha * r).exp()
    }

    /// The smallest diameter (mm) whose return at `r` reaches `floor`, or `None` when none does.
    fn d_min_mm(&self, r: f64, floor: f64) -> Option<f64> {
        let full = self.full_power(r);
        if full < floor {
            return None;
        }
        Some(self.beam_m(r) * (floor / full).sqrt() * 1e3)
    }

    /// Particles per metre of beam at `r` that reach `floor`.
    fn rate(&self, r: f64, floor: f64) -> f64 {
        let Some(d_min) = self.d_min_mm(r, floor) else { return 0.0 };
        let area = std::f64::consts::PI / 4.0 * self.beam_m(r).powi(2);
        area * self.particles.count_above(d_min)
    }

    /// The power of a particle of diameter `d_mm` at `r`.
    fn power(&self, r: f64, d_mm: f64) -> f64 {
        let share = (d_mm * 1e-3 / self.beam_m(r)).powi(2).min(1.0);
        share * self.full_power(r)
    }

    /// The strongest particle in a beam out to `reach_m` that is at least `floor` strong:
    /// `(range, power, class)`. `_alpha` is the medium's extinction (the table's own).
    pub(super) fn strongest(&self, reach_m: f32, floor: f32, _alpha: f32, key: &BeamKey) -> Option<(f32, f32, SemanticClass)> {
        let floor = f64::from(floor);
        // The highest ladder floor at or below the beam's floor.
        let level = ((2.0 * (floor / self.p_min).log2()).floor().max(0.0) as usize).min(LEVELS - 1);
        let row = &self.cumulative[level];
        let reach = (f64::from(reach_m).min(self.max_range_m) - self.min_range_m) / STEP_M;
        if reach <= 0.0 {
            return None;
        }
        let k = (reach as usize).min(row.len() - 1);
        let frac = (reach - k as f64).min(1.0);
        let mean = row[k] + frac * (row.get(k + 1).copied().unwrap_or(row[k]) - row[k]);
        if mean <= 0.0 {
            return None;
        }
        let mut rng = key.rng(Purpose::Weather);
        // Poisson count (mean below a few tens here), by multiplication of uniforms.
        let limit = (-mean).exp();
        let mut count = 0usize;
        let mut prod: f64 = rng.random();
        while prod > limit && count < 1000 {
            count += 1;
            prod *= rng.random::<f64>();
        }
        let ladder = self.level_floor(level);
        let l = self.particles.lambda_per_mm;
        let mut best: Option<(f64, f64)> = None;
        for _ in 0..count {
            // Its place: the inverse of the cumulative rate.
            let u = rng.random::<f64>() * mean;
            let j = row.partition_point(|&c| c < u).clamp(1, row.len() - 1);
            let (c0, c1) = (row[j - 1], row[j]);
            let t = if c1 > c0 { (u - c0) / (c1 - c0) } else { 0.5 };
            let r = self.min_range_m + (j as f64 - 1.0 + t) * STEP_M;
            // Its size: the exponential above the ladder floor's smallest diameter, truncated.
            let Some(d_min) = self.d_min_mm(r, ladder) else { continue };
            let span = 1.0 - (-l * (self.particles.d_max_mm - d_min).max(0.0)).exp();
            let d = d_min - (1.0 - rng.random::<f64>() * span).ln() / l;
            let p = self.power(r, d);
            if p >= floor && best.is_none_or(|(_, bp)| p > bp) {
                best = Some((r, p));
            }
        }
        best.map(|(r, p)| (r as f32, p as f32, self.particles.class))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hdl() -> Measurement {
        crate::Rig::load("hdl64e-roof").unwrap().sensors[0].spec.measurement()
    }

    #[test]
    fn extinction_and_counts_follow_the_distributions() {
        // Marshall-Palmer at 10 mm/h: Lambda = 4.1 R^-0.21 = 2.528 /mm, alpha = pi 8000 / Lambda^3 1e-6.
        let rain = Particles::rain(10.0);
        assert!((rain.lambda_per_mm - 2.528).abs() < 1e-3);
        assert!((rain.extinction_per_m() - 1.56e-3).abs() < 0.02e-3, "{}", rain.extinction_per_m());
        // Its total number density N_0 / Lambda (truncation at 6 mm is negligible).
        assert!((rain.count_above(0.0) - 8000.0 / rain.lambda_per_mm).abs() < 1.0);
        let snow = Particles::snow(2.0);
        assert!((snow.extinction_per_m() - 4.95e-3).abs() < 0.05e-3, "{}", snow.extinction_per_m());
        assert_eq!(Particles::snow(0.0).extinction_per_m(), 0.0);
        assert_eq!(Particles::rain(0.0).count_above(0.0), 0.0);
    }

    /// The mean number of particles a beam reports matches the table's expectation: the Poisson
    /// draws and the thinning are unbiased.
    #[test]
    fn draws_follow_the_expected_count() {
        let m = hdl();
        let t = ParticleTable::new(&Particles::snow(2.0), &m);
        let floor = t.p_min as f32;
        let expected_any = 1.0 - (-t.cumulative[0][((30.0 - t.min_range_m) / STEP_M) as usize]).exp();
        let n = 20_000;
        let seen = (0..n)
            .filter(|&c| {
                let key = BeamKey { seed: 3, frame: 0, sensor: 0, ring: 0, column: c };
                t.strongest(30.0, floor, 0.0, &key).is_some()
            })
            .count() as f64
            / n as f64;
        assert!((seen - expected_any).abs() < 0.02, "{seen} vs {expected_any}");
        // A stronger floor (a bright target) leaves fewer.
        let strong = (0..n)
            .filter(|&c| {
                let key = BeamKey { seed: 3, frame: 0, sensor: 0, ring: 0, column: c };
                t.strongest(30.0, 0.05, 0.0, &key).is_some()
            })
            .count() as f64
            / n as f64;
        assert!(strong < 0.5 * seen, "{strong} vs {seen}");
    }
}
