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
//!   cumulative rate for floors on a factor-sqrt(2) ladder; a beam draws the ladder band of its
//!   strongest particle directly and only the one to few particles in it
//!   ([`ParticleTable::strongest`]), and the strongest one that beats the floor is the medium's
//!   return.

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
const STEP_M: f64 = 0.1;

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
    /// `by_reach[k][level]`: expected particles in `[min_range, min_range + k STEP)` that could
    /// beat floor `level` (a beam reads one row; `level = LEVELS` is 0).
    by_reach: Vec<[f64; LEVELS + 1]>,
    /// `exp(-by_reach[k][level])`: the chance that none does.
    survival: Vec<[f64; LEVELS + 1]>,
    /// The ladder's floors, `p_min 2^(level / 2)` for `level = 0 ..= LEVELS`.
    floors: [f64; LEVELS + 1],
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
            by_reach: Vec::new(),
            survival: Vec::new(),
            floors: [0.0; LEVELS + 1],
        };
        for (level, f) in t.floors.iter_mut().enumerate() {
            *f = t.p_min * 2f64.powf(level as f64 / 2.0);
        }
        let steps = ((t.max_range_m - t.min_range_m) / STEP_M).ceil().max(1.0) as usize;
        t.by_reach = vec![[0.0; LEVELS + 1]; steps + 1];
        for level in 0..LEVELS {
            let floor = t.floors[level];
            for k in 0..steps {
                let r = t.min_range_m + (k as f64 + 0.5) * STEP_M;
                t.by_reach[k + 1][level] = t.by_reach[k][level] + t.rate(r, floor) * STEP_M;
            }
        }
        t.survival = t.by_reach.iter().map(|row| row.map(|m| (-m).exp())).collect();
        t
    }

    /// Beam diameter at `r`, m.
    fn beam_m(&self, r: f64) -> f64 {
        APERTURE_M + self.divergence_rad * r
    }

    /// Power of a whole-beam return at `r` (a particle covering the beam).
    fn full_power(&self, r: f64) -> f64 {
        self.particles.reflectance * (self.r_ref / r).powi(2) * super::fog::overlap(r) * (-2.0 * self.alpha * r).exp()
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

    /// The expected number of particles out to `reach_m` that beat ladder floor `level`.
    #[cfg(test)]
    fn mean(&self, level: usize, reach_m: f64) -> f64 {
        let reach = (reach_m - self.min_range_m) / STEP_M;
        let last = self.by_reach.len() - 1;
        let k = (reach as usize).min(last);
        let frac = (reach - k as f64).min(1.0);
        let (a, b) = (self.by_reach[k][level], self.by_reach[(k + 1).min(last)][level]);
        a + frac * (b - a)
    }

    /// The strongest particle in a beam out to `reach_m` that is at least `floor` strong:
    /// `(range, power, class)`.
    ///
    /// The particles beating ladder floor `L` are a Poisson process whose mean `m_L` falls with
    /// `L`, nested in those beating `L - 1`. The strongest particle lies in the band of the highest
    /// level with any particle: with one uniform `u`, that is the highest `L` with
    /// `exp(-m_L) < u` (`m_L > -ln u`), found by bisection. Its band holds a zero-truncated
    /// Poisson number of particles (mean `m_L - m_(L+1)`), each placed by the band's cumulative
    /// rate along the beam and sized between the two floors' smallest diameters there; the
    /// strongest of them is the return, if it beats `floor` itself (floors between ladder steps).
    /// Exact, and a beam draws one to a few particles however many are in it.
    pub(super) fn strongest(&self, reach_m: f32, floor: f32, key: &BeamKey) -> Option<(f32, f32, SemanticClass)> {
        let floor = f64::from(floor);
        let reach = (f64::from(reach_m).min(self.max_range_m) - self.min_range_m) / STEP_M;
        if reach <= 0.0 {
            return None;
        }
        // The highest ladder floor at or below the beam's floor.
        let base = last_true(0, LEVELS, |l| self.floors[l] <= floor);
        let last = self.by_reach.len() - 1;
        let k0 = (reach as usize).min(last);
        let frac = (reach - k0 as f64).min(1.0);
        let (s_a, s_b) = (&self.survival[k0], &self.survival[(k0 + 1).min(last)]);
        let survival = |level: usize| s_a[level] + frac * (s_b[level] - s_a[level]);
        let mut rng = key.rng(Purpose::Weather);
        // One uniform: particles beat floor L iff u > P(none does) = S_L (S grows with L).
        let u = rng.random::<f64>();
        if survival(base) >= u {
            return None;
        }
        // S_base < u; S_LEVELS = 1 >= u.
        let level = last_true(base, LEVELS + 1, |l| survival(l) < u);
        let (m_a, m_b) = (&self.by_reach[k0], &self.by_reach[(k0 + 1).min(last)]);
        let mean = |level: usize| m_a[level] + frac * (m_b[level] - m_a[level]);
        let band = (mean(level) - mean(level + 1)).max(0.0);
        // The band's count given at least one: inverse CDF of the zero-truncated Poisson, with
        // P(0) = exp(-band) = S_L / S_(L+1).
        let count = {
            let p0 = (survival(level) / survival(level + 1)).min(1.0);
            let target = p0 + rng.random::<f64>() * (1.0 - p0);
            let (mut k, mut pk, mut cdf) = (0usize, p0, p0);
            while cdf < target && k < 64 {
                k += 1;
                pk *= band / k as f64;
                cdf += pk;
            }
            k.max(1)
        };
        let (lower, upper) = (self.floors[level], self.floors[level + 1]);
        let l = self.particles.lambda_per_mm;
        let last = (k0 + 1).min(last);
        let band_at = |j: usize| self.by_reach[j][level] - self.by_reach[j][level + 1];
        let total = band;
        let mut best: Option<(f64, f64)> = None;
        for _ in 0..count {
            // Its place: the inverse of the band's cumulative rate (non-decreasing along the beam).
            let w = rng.random::<f64>() * total;
            let a = last_true(0, last, |j| band_at(j) < w);
            let (c0, c1) = (band_at(a), band_at(a + 1));
            let t = if c1 > c0 { ((w - c0) / (c1 - c0)).clamp(0.0, 1.0) } else { 0.5 };
            let r = self.min_range_m + (a as f64 + t) * STEP_M;
            if r >= f64::from(reach_m) {
                continue; // at the target: its pulse and the target's are one
            }
            // Its size: the exponential between the two floors' smallest diameters there.
            let full = self.full_power(r);
            if full < lower {
                continue;
            }
            let beam_mm = self.beam_m(r) * 1e3;
            let d_lo = beam_mm * (lower / full).sqrt();
            let d_hi = if full >= upper { beam_mm * (upper / full).sqrt() } else { f64::INFINITY };
            let d_hi = d_hi.min(self.particles.d_max_mm);
            let span = 1.0 - (-l * (d_hi - d_lo).max(0.0)).exp();
            let d = d_lo - (1.0 - rng.random::<f64>() * span).ln() / l;
            let p = (d / beam_mm).powi(2).min(1.0) * full;
            if p >= floor && best.is_none_or(|(_, bp)| p > bp) {
                best = Some((r, p));
            }
        }
        best.map(|(r, p)| (r as f32, p as f32, self.particles.class))
    }
}

/// The largest `i` in `lo..hi` with `below(i)`, for a `below` that holds at `lo` (or nowhere:
/// then `lo`) and is true up to some index and false after: a bisection without data-dependent
/// branches (the selects compile to conditional moves; a branchy search mispredicts about half
/// its steps, which cost more than the rest of a beam's weather).
#[inline]
fn last_true(lo: usize, hi: usize, below: impl Fn(usize) -> bool) -> usize {
    let (mut base, mut len) = (lo, hi - lo);
    while len > 1 {
        let half = len / 2;
        base = if below(base + half) { base + half } else { base };
        len -= half;
    }
    base
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
        let expected_any = 1.0 - (-t.mean(0, 30.0)).exp();
        let n = 20_000;
        let seen = (0..n)
            .filter(|&c| {
                let key = BeamKey { seed: 3, frame: 0, sensor: 0, ring: 0, column: c };
                t.strongest(30.0, floor, &key).is_some()
            })
            .count() as f64
            / n as f64;
        assert!((seen - expected_any).abs() < 0.02, "{seen} vs {expected_any}");
        // A stronger floor (a bright target) leaves fewer.
        let strong = (0..n)
            .filter(|&c| {
                let key = BeamKey { seed: 3, frame: 0, sensor: 0, ring: 0, column: c };
                t.strongest(30.0, 0.05, &key).is_some()
            })
            .count() as f64
            / n as f64;
        assert!(strong < 0.5 * seen, "{strong} vs {seen}");
    }

    /// Floors between the ladder's steps: the share of beams whose strongest particle beats the
    /// floor is `1 - exp(-m)`, `m` the rate of such particles integrated along the beam directly.
    #[test]
    fn the_strongest_particle_beats_any_floor_at_its_rate() {
        let m = hdl();
        for particles in [Particles::snow(1.0), Particles::rain(30.0)] {
            let t = ParticleTable::new(&particles, &m);
            for (floor, reach) in [(t.p_min * 2f64.powf(0.3), 40.0), (t.p_min * 37.0, 25.0), (0.02, 12.0)] {
                let steps = ((reach - t.min_range_m) / (STEP_M / 10.0)) as usize;
                let mean: f64 = (0..steps)
                    .map(|k| t.rate(t.min_range_m + (k as f64 + 0.5) * STEP_M / 10.0, floor) * STEP_M / 10.0)
                    .sum();
                let expected = 1.0 - (-mean).exp();
                let n = 20_000;
                let seen = (0..n)
                    .filter(|&c| {
                        let key = BeamKey { seed: 5, frame: 1, sensor: 0, ring: 2, column: c };
                        t.strongest(reach as f32, floor as f32, &key).is_some_and(|(r, p, _)| {
                            assert!(f64::from(p) >= floor * 0.999 && f64::from(r) <= reach + 1e-3);
                            true
                        })
                    })
                    .count() as f64
                    / n as f64;
                eprintln!("{:?} floor {floor}: {seen} vs {expected}", particles.class);
                assert!((seen - expected).abs() < 0.015, "{:?} floor {floor}: {seen} vs {expected}", particles.class);
            }
        }
    }
}
