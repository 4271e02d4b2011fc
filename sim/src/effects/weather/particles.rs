//! Rain drops and snowflakes in the beam: drawn per beam from their size distributions, each
//! returning what its backscatter cross-section sends into the receiver.
//!
//! - **Sizes**: exponential, `N(D) = N_0 exp(-Lambda D)` per m^3 per mm. Rain: Marshall-Palmer
//!   (1948), `N_0 = 8000`, `Lambda = 4.1 R^-0.21` (R in mm/h), drops up to 6 mm. Snow: Sekhon and
//!   Srivastava (1970, J. Atmos. Sci. 27, 299: radar-measured snow spectra) in melted diameters,
//!   `N_0 = 2500 R^-0.94`, `Lambda = 2.29 R^-0.45`, flakes of density 0.1 g/cm^3 (diameter
//!   `10^(1/3) = 2.15` times the melted one, as in Hahner et al., CVPR 2022), up to 20 mm. (Gunn
//!   and Marshall 1958, `N_0 = 3800 R^-0.87`, `Lambda = 2.55 R^-0.48`, has 1.5 times the flakes and
//!   a tail that grows faster with the rate: it puts 3 mm/h above WADS's band.)
//! - **Projected area** `A(D) = gamma D^sigma`: drops are spheres (`pi/4 D^2`); snowflakes are
//!   aggregates whose projected area is Mitchell's (1996, J. Atmos. Sci. 53, 1710: aggregates of
//!   side planes, bullets and columns, `A = 0.2285 D^1.88` in cgs, i.e. `0.301 D^1.88` mm^2 with D
//!   in mm): 38 % of the disk at 1 mm, 32 % at 5 mm.
//! - **Extinction** from the same distribution, geometric optics (extinction efficiency 2):
//!   `alpha = 2 int A(D) N(D) dD = 2 gamma N_0 Gamma(sigma + 1) / Lambda^(sigma + 1)`: 1.6e-3 /m
//!   in rain of 10 mm/h, 1.3e-3 /m in snow of 2 mm/h.
//! - **A particle's return**: backscatter cross-section per steradian `sigma_pi = 2 A / S`, `S`
//!   the particle's lidar ratio (extinction over backscatter, sr). In the intensity model's units
//!   (a Lambertian target of reflectance `rho` filling the beam returns `rho (r_ref / R)^2`), a
//!   particle returns `rho_p min(1, A(D) / A_beam(R)) (r_ref / R)^2 xi(R) exp(-2 alpha R)` with the
//!   equivalent reflectance `rho_p = pi sigma_pi / A = 2 pi / S`. Snow: ice crystals' lidar ratio
//!   `S = 29 sr` (Chen, Chiang and Nee 2002, Appl. Opt. 41, 6470: cirrus, 29 +- 12 sr; large ice
//!   particles scatter by geometric optics, so the figure holds at 905 nm): `rho_p = 0.217`. Rain:
//!   [`RAIN_LIDAR_RATIO_SR`], 40 sr, `rho_p = 0.157`, the one rain constant set by a measurement
//!   (Linnhoff et al. 2022's VLP-16 in natural rain, docs/weather.md), as snow's receiver is set by
//!   WADS.
//! - **The beam**: diameter `d(R) = d_0 + theta R`, `d_0` = 11 mm, the exit spot of a spinning
//!   unit's lens (Velodyne VLP-16 user manual: 9.5 x 12.7 mm at the exit, the same area as a
//!   disk of 11 mm), `theta` the sensor's divergence.
//! - **The receiver's near-range overlap** `xi(R)` ([`bistatic_overlap`]): transmitter and
//!   receiver are side-by-side lenses of the same aperture `d_0` whose axes lie
//!   [`AXIS_SEPARATION_M`] apart, the receiver's field of view [`RECEIVER_FOV_PER_DIVERGENCE`]
//!   times the beam's divergence; `xi` is the share of the beam's spot inside the receiver's field
//!   (two circles' intersection over the spot's area): none before 4.0 m, full from 34.7 m. A
//!   bright hard target is seen from far nearer (its power is thousands of times the threshold);
//!   a flake, near the threshold, is not. Fog keeps Hahner et al.'s overlap (0.9-1.0 m), with
//!   which its constants were set.
//! - **Per beam**: the particles that could beat the beam's floor (the threshold, or the target's
//!   power when it is stronger: the strongest return wins) form a Poisson process along the beam,
//!   of rate `A_beam(R) int_{D_min(R)} N(D) dD` per metre. A table holds its cumulative rate for
//!   floors on a factor-sqrt(2) ladder; a beam draws the ladder band of its strongest particle
//!   directly and only the one to few particles in it ([`ParticleTable::strongest`]), and the
//!   strongest one that beats the floor is the medium's return.

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
    /// Equivalent reflectance of a particle that fills the beam: `2 pi / S`, `S` its lidar ratio
    /// (module docs).
    pub reflectance: f64,
    /// Projected area `gamma D^sigma` (mm^2, D in mm): `gamma`.
    pub area_coefficient_mm2: f64,
    /// Projected area `gamma D^sigma`: `sigma`.
    pub area_exponent: f64,
    /// The class of its returns.
    pub class: SemanticClass,
}

/// Flake diameter per melted diameter at a snow density of 0.1 g/cm^3: `10^(1/3)`.
const FLAKE_PER_MELTED: f64 = 2.154_434_690_031_884;
/// The beam's diameter at the exit aperture, m: the VLP-16's exit spot, 9.5 x 12.7 mm (its user
/// manual), as a disk of the same area.
pub const APERTURE_M: f64 = 0.011;
/// Distance between the transmitter's and the receiver's optical axes, m (side-by-side lenses of
/// [`APERTURE_M`] with a 15 mm gap between them). With the receiver's field below, the overlap
/// starts at 4.0 m and is full from 34.7 m. Not from a datasheet: this and the receiver's field
/// are the two figures set by a measurement, WADS's labelled snowfall (no flakes nearer than 3 m,
/// median 6.5-6.9 m, a few per cent of the returns; docs/weather.md).
pub const AXIS_SEPARATION_M: f64 = 0.026;
/// The receiver's field of view per beam divergence (full angles): 1.5, a field a little wider
/// than the beam so that the beam stays in it at long range. Set with [`AXIS_SEPARATION_M`] by
/// WADS's figures.
pub const RECEIVER_FOV_PER_DIVERGENCE: f64 = 1.5;
/// Lidar ratio (extinction over backscatter) of ice particles, sr: 29 sr (Chen, Chiang and Nee
/// 2002, cirrus clouds).
pub const ICE_LIDAR_RATIO_SR: f64 = 29.0;
/// Lidar ratio (extinction over backscatter) of raindrops at 905 nm, sr: 40 sr (a drop returns
/// `2 pi / 40 = 0.157` of what a white disk of its size would; a backscatter efficiency of 0.63).
/// Not from a published figure (none for millimetre drops at 905 nm was at hand): set by the
/// measurement rain is calibrated against, Linnhoff et al. 2022 (Sensors 22, 5266; a VLP-16 in
/// natural rain: a sky beam returns a drop with probability 1.69e-4 per mm/h), which puts our
/// `vlp16-roof` at 0.58, 1.06 and 1.94 times it at 10, 20 and 50 mm/h (docs/weather.md). Before:
/// 0.05, assumed, with which no drop was ever detected.
pub const RAIN_LIDAR_RATIO_SR: f64 = 40.0;
/// Mitchell (1996) projected area of aggregates, `A = 0.2285 D^1.88` (cm^2, D in cm), in mm^2 with
/// D in mm: `100 * 0.2285 * 10^-1.88`.
const AGGREGATE_AREA_COEFFICIENT_MM2: f64 = 0.301_22;
/// Mitchell (1996): the exponent of the aggregates' projected area.
const AGGREGATE_AREA_EXPONENT: f64 = 1.88;

impl Particles {
    /// Rain of `rate_mm_h` (Marshall-Palmer).
    pub fn rain(rate_mm_h: f64) -> Self {
        let r = rate_mm_h.max(1e-6);
        Self {
            n0_per_m3_mm: if rate_mm_h > 0.0 { 8000.0 } else { 0.0 },
            lambda_per_mm: 4.1 * r.powf(-0.21),
            d_max_mm: 6.0,
            reflectance: 2.0 * std::f64::consts::PI / RAIN_LIDAR_RATIO_SR,
            area_coefficient_mm2: std::f64::consts::FRAC_PI_4,
            area_exponent: 2.0,
            class: SemanticClass::RAIN,
        }
    }

    /// Snow of `rate_mm_h` of water (Sekhon-Srivastava, flakes of density 0.1 g/cm^3).
    pub fn snow(rate_mm_h: f64) -> Self {
        let r = rate_mm_h.max(1e-6);
        let (n0, lambda) = (2500.0 * r.powf(-0.94), 2.29 * r.powf(-0.45));
        Self {
            n0_per_m3_mm: if rate_mm_h > 0.0 { n0 / FLAKE_PER_MELTED } else { 0.0 },
            lambda_per_mm: lambda / FLAKE_PER_MELTED,
            d_max_mm: 20.0,
            reflectance: 2.0 * std::f64::consts::PI / ICE_LIDAR_RATIO_SR,
            area_coefficient_mm2: AGGREGATE_AREA_COEFFICIENT_MM2,
            area_exponent: AGGREGATE_AREA_EXPONENT,
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

    /// Extinction coefficient, 1/m: `2 int A(D) N(D) dD = 2 gamma N_0 Gamma(sigma + 1) /
    /// Lambda^(sigma + 1)` (the untruncated tail is negligible).
    pub fn extinction_per_m(&self) -> f64 {
        let sigma = self.area_exponent;
        2.0 * self.area_coefficient_mm2 * self.n0_per_m3_mm * gamma_fn(sigma + 1.0)
            / self.lambda_per_mm.powf(sigma + 1.0)
            * 1e-6
    }

    /// Projected area of a particle of diameter `d_mm`, mm^2.
    pub fn area_mm2(&self, d_mm: f64) -> f64 {
        self.area_coefficient_mm2 * d_mm.powf(self.area_exponent)
    }

    /// The diameter (mm) whose projected area is `area_mm2`.
    fn diameter_of_area_mm(&self, area_mm2: f64) -> f64 {
        (area_mm2 / self.area_coefficient_mm2).powf(1.0 / self.area_exponent)
    }
}

/// The gamma function for `x > 0` (Lanczos, g = 7, nine terms: 15 digits).
fn gamma_fn(x: f64) -> f64 {
    const G: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        return std::f64::consts::PI / ((std::f64::consts::PI * x).sin() * gamma_fn(1.0 - x));
    }
    let x = x - 1.0;
    let t = x + 7.5;
    let sum = G.iter().enumerate().skip(1).fold(G[0], |acc, (i, g)| acc + g / (x + i as f64));
    (2.0 * std::f64::consts::PI).sqrt() * t.powf(x + 0.5) * (-t).exp() * sum
}

/// The share of a beam's spot at `range_m` that the receiver sees: the intersection of the spot
/// (diameter `APERTURE_M + theta R`) and the receiver's field (`APERTURE_M + k theta R`, `k` =
/// [`RECEIVER_FOV_PER_DIVERGENCE`]), their centres [`AXIS_SEPARATION_M`] apart, over the spot's
/// area. 0 for a beam without divergence (its spot never meets the field).
pub fn bistatic_overlap(range_m: f64, divergence_rad: f64) -> f64 {
    let a = 0.5 * (APERTURE_M + divergence_rad * range_m);
    let b = 0.5 * (APERTURE_M + RECEIVER_FOV_PER_DIVERGENCE * divergence_rad * range_m);
    let s = AXIS_SEPARATION_M;
    if s >= a + b {
        return 0.0;
    }
    if s <= (b - a).abs() {
        return (a.min(b) / a).powi(2);
    }
    let alpha = ((s * s + a * a - b * b) / (2.0 * s * a)).clamp(-1.0, 1.0).acos();
    let beta = ((s * s + b * b - a * a) / (2.0 * s * b)).clamp(-1.0, 1.0).acos();
    let kite = 0.5 * ((-s + a + b) * (s + a - b) * (s - a + b) * (s + a + b)).max(0.0).sqrt();
    // (Clamped: at tangency the three terms cancel to a rounding error of either sign.)
    ((a * a * alpha + b * b * beta - kite) / (std::f64::consts::PI * a * a)).clamp(0.0, 1.0)
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
    /// [`ParticleTable::candidate_chance`].
    candidate_chance: f64,
}

impl ParticleTable {
    /// The table for `particles` and a sensor measuring with `m`.
    pub fn new(particles: &Particles, m: &Measurement) -> Self {
        let mut t = Self {
            particles: *particles,
            p_min: f64::from(super::range_gate_threshold(m)),
            r_ref: f64::from(m.intensity_reference_m),
            alpha: particles.extinction_per_m(),
            divergence_rad: f64::from(m.beam_divergence_rad),
            min_range_m: f64::from(m.min_range_m).max(super::fog::OVERLAP_M.0),
            max_range_m: f64::from(m.max_range_m),
            by_reach: Vec::new(),
            survival: Vec::new(),
            floors: [0.0; LEVELS + 1],
            candidate_chance: 0.0,
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
        t.candidate_chance = 1.0 - t.survival.iter().map(|s| s[0]).fold(1.0, f64::min);
        t
    }

    /// The chance that a beam reaching the maximum range holds a particle that beats the
    /// sensor's threshold: no beam's chance is higher (a beam's floor is at least the threshold,
    /// its reach at most the maximum range), so a row draws its candidate beams with this chance
    /// and each candidate keeps its particle with its own chance over this one
    /// ([`ParticleTable::strongest_candidate`]): thinning, exact, and the other beams of the row
    /// draw nothing.
    pub(super) fn candidate_chance(&self) -> f64 {
        self.candidate_chance
    }

    /// Beam diameter at `r`, m.
    fn beam_m(&self, r: f64) -> f64 {
        APERTURE_M + self.divergence_rad * r
    }

    /// Power of a whole-beam return at `r` (a particle covering the beam the receiver sees).
    fn full_power(&self, r: f64) -> f64 {
        self.particles.reflectance
            * (self.r_ref / r).powi(2)
            * bistatic_overlap(r, self.divergence_rad)
            * (-2.0 * self.alpha * r).exp()
    }

    /// The beam's cross-section at `r`, mm^2.
    fn beam_area_mm2(&self, r: f64) -> f64 {
        std::f64::consts::FRAC_PI_4 * (self.beam_m(r) * 1e3).powi(2)
    }

    /// The power of a particle of diameter `d_mm` at `r` whose whole-beam power there is `full`.
    fn power(&self, d_mm: f64, r: f64, full: f64) -> f64 {
        (self.particles.area_mm2(d_mm) / self.beam_area_mm2(r)).min(1.0) * full
    }

    /// The smallest diameter (mm) whose return at `r` reaches `floor`, or `None` when none does.
    fn d_min_mm(&self, r: f64, floor: f64) -> Option<f64> {
        let full = self.full_power(r);
        if full < floor || full <= 0.0 {
            return None;
        }
        Some(self.particles.diameter_of_area_mm(self.beam_area_mm2(r) * floor / full))
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
        self.strongest_with(reach_m, floor, key, None)
    }

    /// [`ParticleTable::strongest`] for a beam its row drew as a candidate with chance
    /// `candidate_chance` ([`ParticleTable::candidate_chance`]): the beam holds a particle with
    /// chance `P / candidate_chance`, `P` its chance as a beam of its own, so that over the row's
    /// draw and this one it holds one with chance `P`, and the particle is drawn as
    /// [`ParticleTable::strongest`] draws it.
    pub(super) fn strongest_candidate(
        &self,
        reach_m: f32,
        floor: f32,
        key: &BeamKey,
        candidate_chance: f64,
    ) -> Option<(f32, f32, SemanticClass)> {
        self.strongest_with(reach_m, floor, key, Some(candidate_chance))
    }

    fn strongest_with(
        &self,
        reach_m: f32,
        floor: f32,
        key: &BeamKey,
        candidate_chance: Option<f64>,
    ) -> Option<(f32, f32, SemanticClass)> {
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
        let v = rng.random::<f64>();
        let s_base = survival(base);
        let u = match candidate_chance {
            None => v,
            // A candidate keeps its particle with chance (1 - S_base) / q; given that, u is
            // uniform on (S_base, 1), as the one uniform above is given u > S_base.
            Some(q) => {
                if v * q >= 1.0 - s_base {
                    return None;
                }
                s_base + v * q
            }
        };
        if s_base >= u {
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
            if full < lower || full <= 0.0 {
                continue;
            }
            let beam_mm2 = self.beam_area_mm2(r);
            let d_lo = self.particles.diameter_of_area_mm(beam_mm2 * lower / full);
            let d_hi =
                if full >= upper { self.particles.diameter_of_area_mm(beam_mm2 * upper / full) } else { f64::INFINITY };
            let d_hi = d_hi.min(self.particles.d_max_mm);
            let span = 1.0 - (-l * (d_hi - d_lo).max(0.0)).exp();
            let d = d_lo - (1.0 - rng.random::<f64>() * span).ln() / l;
            let p = self.power(d, r, full);
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
        // Sekhon-Srivastava at 2 mm/h in flake diameters (N_0 = 604.8 /m^3/mm, Lambda = 0.7781 /mm)
        // with Mitchell's area: alpha = 2 * 0.30122 * N_0 * Gamma(2.88) / Lambda^2.88 = 1.348e-3 /m.
        let snow = Particles::snow(2.0);
        assert!((snow.extinction_per_m() - 1.3476e-3).abs() < 0.001e-3, "{}", snow.extinction_per_m());
        // Aggregates cover 38 % of their disk at 1 mm.
        assert!((snow.area_mm2(1.0) / std::f64::consts::FRAC_PI_4 - 0.3835).abs() < 1e-3);
        assert_eq!(Particles::snow(0.0).extinction_per_m(), 0.0);
        assert_eq!(Particles::rain(0.0).count_above(0.0), 0.0);
    }

    #[test]
    fn gamma_function_matches_known_values() {
        assert!((gamma_fn(3.0) - 2.0).abs() < 1e-12);
        assert!((gamma_fn(0.5) - std::f64::consts::PI.sqrt()).abs() < 1e-12);
        assert!((gamma_fn(2.88) - 1.88 * gamma_fn(1.88)).abs() < 1e-12);
    }

    /// The receiver sees none of the spot before the circles meet, `(s - d_0) / ((1 + k) theta /
    /// 2)` = 4.0 m at 3 mrad, all of it once the field's radius exceeds the spot's by `s`,
    /// `s / ((k - 1) theta / 2)` = 34.7 m, and more with range in between.
    #[test]
    fn the_overlap_follows_the_bistatic_geometry() {
        let theta = 0.003;
        let start = (AXIS_SEPARATION_M - APERTURE_M) / (0.5 * (1.0 + RECEIVER_FOV_PER_DIVERGENCE) * theta);
        let full = AXIS_SEPARATION_M / (0.5 * (RECEIVER_FOV_PER_DIVERGENCE - 1.0) * theta);
        assert!((start - 4.0).abs() < 1e-3 && (full - 34.667).abs() < 1e-3, "{start} {full}");
        assert_eq!(bistatic_overlap(start - 0.01, theta), 0.0);
        assert!(bistatic_overlap(start + 0.05, theta) > 0.0);
        assert!(bistatic_overlap(full - 0.5, theta) < 1.0);
        assert_eq!(bistatic_overlap(full + 0.01, theta), 1.0);
        let xs: Vec<f64> = (0..300).map(|k| bistatic_overlap(k as f64 * 0.1, theta)).collect();
        assert!(xs.windows(2).all(|w| w[0] <= w[1] + 1e-12), "not monotone");
        // Half way the two circles' intersection is a fraction strictly between.
        let mid = bistatic_overlap(15.0, theta);
        assert!(mid > 0.3 && mid < 0.9, "{mid}");
        assert_eq!(bistatic_overlap(50.0, 0.0), 0.0, "a beam without divergence never meets the field");
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
