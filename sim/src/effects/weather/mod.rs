//! Weather per beam: fog, rain and snow decided for every beam as the scan measures it, before a
//! return is chosen, seeded like the rest of the noise (keyed by seed, frame, sensor, ring,
//! column: thread counts cannot change a scan).
//!
//! A sensor in weather measures power, not just distance. In the units of the intensity model
//! ([`crate::effects::measure`]) a return of reflectance `rho cos(theta)` at range `R` has the
//! power `P = rho cos(theta) (r_ref / R)^2` (unsaturated), and the sensor detects it when
//! `P >= P_min`, its detection threshold: `P_min = 0.1 (r_ref / max_range)^2`, a 10 % target at
//! normal incidence seen out to the sensor's maximum range in clear air ([`range_gate_threshold`];
//! each sensor's threshold by its datasheet, [`detection_threshold`], is carried but not applied:
//! docs/weather.md, "Detection thresholds by datasheet"). The medium attenuates a
//! hard target twice (out and back), `T^2 = exp(-2 alpha R)`, and adds returns of its own; the
//! sensor reports the strongest detectable return of the beam, as single-return units do in their
//! strongest mode (other modes: "Return modes" below):
//!
//! - **Fog** (visibility = meteorological optical range `V`, m): extinction `alpha = ln 20 / V`,
//!   backscatter `beta = 0.046 / V` (1/(m sr)); the fog's own return is the pulse-weighted
//!   backscatter of the air in front of the target ([`fog`], after Rasshofer et al. 2011 and the
//!   constants of Hahner et al., ICCV 2021: pulse `tau_H = 20 ns`, overlap from 0.9 to 1.0 m,
//!   their target constant `Gamma = 1e-6`).
//! - **Rain** and **snow** (rate, mm/h of water): drops and flakes drawn per beam from their size
//!   distributions (Marshall-Palmer for rain, Gunn-Marshall for snow with flakes of density
//!   0.1 g/cm^3), anywhere in the beam's cone between the sensor and the target; each returns
//!   `rho_p min(1, A(D) / A_beam(R)) (r_ref / R)^2 xi(R) T^2(R)` (its backscatter cross-section
//!   from its projected area and lidar ratio, the receiver's bistatic overlap `xi`) and the
//!   medium's extinction follows from the same distribution ([`particles`]). Snow is calibrated
//!   on WADS's labelled snowfall and accepted up to [`SNOW_CALIBRATED_MAX_MM_H`]; rain's drops'
//!   backscatter on a VLP-16's rain detections in natural rain (Linnhoff et al. 2022).
//!
//! `clear` applies the detection threshold without a medium: the reference a weather scan is
//! compared with. Returns from the medium get their own classes ([`SemanticClass::FOG`],
//! [`SemanticClass::RAIN`], [`SemanticClass::SNOW`]); every other return keeps its ground truth,
//! its intensity reduced by `T^2`.
//!
//! # Return modes
//! The medium meets the sensor's return mode ([`ReturnMode`], [`SensorWeather::with_return_mode`];
//! a catalogued model's `return_mode`, [`return_mode_of`] for the rest). With `T` the beam's
//! hard target (its first echo) and `M` the medium's candidate return in front of it:
//! - `Strongest` (the default): `M` is reported instead of `T` when it is detectable and at least
//!   as strong as `T` (the medium is drawn against the floor `max(P_T, P_min)`), else `T`.
//! - `Last`: `T` whenever it is detectable (a particle in front never hides it; nothing is drawn);
//!   `M` (drawn against `P_min`) only when there is no detectable target.
//! - `Dual` (two echo planes, nearest first; also every multi-echo model without catalogued modes,
//!   such as the LUX, whose planes are every echo nearest first): `M` whenever it is detectable
//!   (drawn against `P_min`, however strong `T` is) in plane 0, then `T` in plane 1 when it is
//!   detectable; that is both the strongest-and-last pair of Velodyne and Hesai and Ouster's two
//!   strongest when the beam holds these two returns. The beam's later surface echoes (edges) move
//!   back one plane behind `T`, and those beyond the sensor's planes are dropped
//!   (`crate::scan`).
//!
//! The medium's return is its strongest particle (or the fog's backscatter peak) in every mode;
//! a real `Last` or `Dual` unit would report the last of several detectable particles, but a
//! beam rarely holds more than one. Later surface echoes are left as they are (not attenuated).

pub mod fog;
pub mod particles;

use std::sync::Arc;

use rand::RngExt;
use serde::{Deserialize, Serialize};

use crate::error::{Result, SimError};
use crate::noise::{BeamKey, Purpose, RowKey};
use crate::scene::SemanticClass;
use crate::sensor::{Measurement, ReturnMode, SensorSpec};

/// The largest snowfall rate accepted, mm/h of water: the calibrated range (docs/weather.md). A
/// larger rate is refused, naming this range.
pub const SNOW_CALIBRATED_MAX_MM_H: f64 = 5.0;

/// The largest rain rate accepted, mm/h: the range over which rain was compared with its
/// measurement and found within a factor 2 (10-50 mm/h; docs/weather.md). A larger rate is refused,
/// naming this range.
pub const RAIN_CALIBRATED_MAX_MM_H: f64 = 50.0;

/// A rate within `0 ..= max_mm_h`, or an error naming the calibrated range of `kind`.
fn check_calibrated(rate_mm_h: f64, max_mm_h: f64, kind: &str, measured: &str) -> Result<()> {
    if rate_mm_h.is_finite() && (0.0..=max_mm_h).contains(&rate_mm_h) {
        Ok(())
    } else {
        Err(SimError::invalid(
            "weather.rate_mm_h",
            rate_mm_h,
            format!(
                "0 ..= {max_mm_h} ({kind} is calibrated on measured {measured} up to {max_mm_h} mm/h of water; docs/weather.md)"
            ),
        ))
    }
}

/// The weather of a scan.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum Weather {
    /// Clear air: the sensors' detection thresholds, no medium.
    Clear,
    /// Fog of the given visibility (meteorological optical range, metres, 1 ..= 100,000).
    Fog {
        /// Visibility, metres.
        visibility_m: f64,
    },
    /// Rain of the given rate (mm/h, 0 ..= [`RAIN_CALIBRATED_MAX_MM_H`]).
    Rain {
        /// Rain rate, millimetres per hour.
        rate_mm_h: f64,
    },
    /// Snow of the given rate (mm/h of water, 0 ..= 5, the calibrated range).
    Snow {
        /// Snowfall rate (liquid water equivalent), millimetres per hour.
        rate_mm_h: f64,
    },
}

impl Weather {
    /// The kinds `parse` takes.
    pub const KINDS: [&'static str; 4] = ["clear", "fog", "rain", "snow"];

    /// Parses `clear`, `fog:visibility_m=50`, `rain:rate_mm_h=10` or `snow:rate_mm_h=2`, and
    /// validates the value.
    ///
    /// ```
    /// use sim::effects::weather::Weather;
    /// assert_eq!(Weather::parse("fog:visibility_m=50")?, Weather::Fog { visibility_m: 50.0 });
    /// assert!(Weather::parse("fog:visibility_m=0.5").unwrap_err().to_string().contains("visibility_m"));
    /// assert!(Weather::parse("hail:rate_mm_h=3").unwrap_err().to_string().contains("clear, fog, rain, snow"));
    /// # Ok::<(), sim::SimError>(())
    /// ```
    pub fn parse(spec: &str) -> Result<Self> {
        let (kind, rest) = spec.split_once(':').unwrap_or((spec, ""));
        let mut fields = Vec::new();
        for part in rest.split(',').filter(|p| !p.trim().is_empty()) {
            let Some((k, v)) = part.split_once('=') else {
                return Err(SimError::invalid("weather", part, "FIELD=VALUE, e.g. fog:visibility_m=50"));
            };
            let value: f64 = v
                .trim()
                .parse()
                .map_err(|_| SimError::invalid(format!("weather.{}", k.trim()), v.trim(), "a number"))?;
            fields.push((k.trim(), value));
        }
        let one = |name: &str| -> Result<f64> {
            match fields.as_slice() {
                [(k, v)] if *k == name => Ok(*v),
                [(k, _)] => {
                    Err(SimError::invalid(format!("weather.{k}"), "an unknown field", format!("{kind} takes {name}")))
                }
                _ => Err(SimError::invalid("weather", spec, format!("{kind}:{name}=VALUE"))),
            }
        };
        let w = match kind.trim() {
            "clear" if fields.is_empty() => Weather::Clear,
            "clear" => return Err(SimError::invalid("weather", spec, "`clear` takes no fields")),
            "fog" => Weather::Fog { visibility_m: one("visibility_m")? },
            "rain" => Weather::Rain { rate_mm_h: one("rate_mm_h")? },
            "snow" => Weather::Snow { rate_mm_h: one("rate_mm_h")? },
            other => return Err(SimError::invalid("weather kind", other, Self::KINDS.join(", "))),
        };
        w.validate()?;
        Ok(w)
    }

    /// Checks the value, naming the field and its allowed range.
    pub fn validate(&self) -> Result<()> {
        let check = |name: &str, v: f64, lo: f64, hi: f64| {
            if v.is_finite() && (lo..=hi).contains(&v) {
                Ok(())
            } else {
                Err(SimError::invalid(format!("weather.{name}"), v, format!("{lo} ..= {hi}")))
            }
        };
        match *self {
            Weather::Clear => Ok(()),
            Weather::Fog { visibility_m } => check("visibility_m", visibility_m, 1.0, 100_000.0),
            Weather::Rain { rate_mm_h } => check_calibrated(rate_mm_h, RAIN_CALIBRATED_MAX_MM_H, "rain", "rain"),
            Weather::Snow { rate_mm_h } => check_calibrated(rate_mm_h, SNOW_CALIBRATED_MAX_MM_H, "snow", "snowfall"),
        }
    }

    /// The extinction coefficient of the medium, 1/m (the hard target's power falls as
    /// `exp(-2 alpha R)`).
    pub fn extinction_per_m(&self) -> f64 {
        match *self {
            Weather::Clear => 0.0,
            Weather::Fog { visibility_m } => fog::extinction_per_m(visibility_m),
            Weather::Rain { rate_mm_h } => particles::Particles::rain(rate_mm_h).extinction_per_m(),
            Weather::Snow { rate_mm_h } => particles::Particles::snow(rate_mm_h).extinction_per_m(),
        }
    }

    /// A short text: `fog:visibility_m=50`.
    pub fn spec(&self) -> String {
        match *self {
            Weather::Clear => "clear".into(),
            Weather::Fog { visibility_m } => format!("fog:visibility_m={visibility_m}"),
            Weather::Rain { rate_mm_h } => format!("rain:rate_mm_h={rate_mm_h}"),
            Weather::Snow { rate_mm_h } => format!("snow:rate_mm_h={rate_mm_h}"),
        }
    }
}

/// The detection threshold of a sensor by its datasheet, in the intensity model's power units: the
/// datasheet's target seen out to the datasheet's range, `rho_spec (r_ref / R_spec)^2`
/// ([`Measurement::detection_reflectance`], [`Measurement::detection_range_m`]; docs/sensors.md,
/// "Detection figures"). Not yet the weather's threshold: with it every sensor but the Pandar64
/// sees almost no snow under the receiver calibrated on WADS, and no receiver geometry brings the
/// OS1-128 back to WADS's median range (docs/weather.md, "Detection thresholds by datasheet").
pub fn detection_threshold(m: &Measurement) -> f32 {
    m.detection_reflectance * (m.intensity_reference_m / m.detection_range_m).powi(2)
}

/// The threshold the weather applies (module docs): `0.1 (r_ref / max_range)^2`, a 10 % target
/// at normal incidence out to the range gate, the rule with which fog's constants were taken from
/// Hahner et al. and snow's receiver was fitted to WADS. It equals [`detection_threshold`] only
/// where the datasheet's figure is a 10 % target at `max_range_m` (the Pandar64).
pub fn range_gate_threshold(m: &Measurement) -> f32 {
    0.1 * (m.intensity_reference_m / m.max_range_m).powi(2)
}

/// The unsaturated power of a return of intensity `intensity` (the saturated model's value) at
/// `range_m`: the intensity model without its saturation below `r_ref`.
pub fn unsaturated_power(m: &Measurement, intensity: f32, range_m: f32) -> f32 {
    intensity * (m.intensity_reference_m / range_m).powi(2).max(1.0)
}

/// What the weather makes of one beam.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BeamOutcome {
    /// The target's return, its intensity reduced by the medium.
    Target {
        /// Its intensity, `[0, 1]`.
        intensity: f32,
    },
    /// A return from the medium (fog) or a particle (drop, flake) at `range_m`.
    Medium {
        /// Its range, metres.
        range_m: f32,
        /// Its intensity, `[0, 1]`.
        intensity: f32,
        /// Its class ([`SemanticClass::FOG`], [`SemanticClass::RAIN`] or [`SemanticClass::SNOW`]).
        class: SemanticClass,
    },
    /// Nothing detectable.
    Lost,
}

/// What the weather makes of one beam in the sensor's return mode: the nearest echo it reports
/// and, in [`ReturnMode::Dual`] when that echo is the medium's, the target's echo behind it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BeamEchoes {
    /// The nearest reported echo (the only one in `Strongest` and `Last`).
    pub first: BeamOutcome,
    /// `Dual` only, when [`BeamEchoes::first`] is the medium's: the intensity of the target's
    /// echo behind it (reduced by the medium), or `None` when the target is not detectable.
    pub target_behind: Option<f32>,
}

/// The return mode in which the weather meets the sensor `spec` measuring with `m`: a catalogued
/// model's `return_mode`; [`ReturnMode::Dual`] (every echo, nearest first) for the other models
/// when they report several echoes (`m.max_echoes > 1`: the LUX's three), else
/// [`ReturnMode::Strongest`].
pub fn return_mode_of(spec: &SensorSpec, m: &Measurement) -> ReturnMode {
    match spec.catalogued() {
        Some((_, settings)) => settings.return_mode(),
        None if m.max_echoes > 1 => ReturnMode::Dual,
        None => ReturnMode::Strongest,
    }
}

/// The medium as one sensor sees it.
#[derive(Clone, Debug)]
enum Medium {
    None,
    Fog(Arc<fog::FogTable>),
    Particles(Arc<particles::ParticleTable>),
}

/// The weather for one sensor: its threshold, the medium's extinction, the tables of its own
/// returns and the sensor's return mode, built once per scan.
#[derive(Clone, Debug)]
pub struct SensorWeather {
    alpha_per_m: f32,
    p_min: f32,
    m: Measurement,
    medium: Medium,
    mode: ReturnMode,
}

impl SensorWeather {
    /// The weather `w` for a sensor measuring with `m`.
    pub fn new(w: &Weather, m: &Measurement) -> Self {
        let alpha_per_m = w.extinction_per_m() as f32;
        let medium = match *w {
            Weather::Clear => Medium::None,
            Weather::Fog { visibility_m } => Medium::Fog(fog::FogTable::cached(visibility_m, m)),
            Weather::Rain { rate_mm_h } => {
                Medium::Particles(Arc::new(particles::ParticleTable::new(&particles::Particles::rain(rate_mm_h), m)))
            }
            Weather::Snow { rate_mm_h } => {
                Medium::Particles(Arc::new(particles::ParticleTable::new(&particles::Particles::snow(rate_mm_h), m)))
            }
        };
        Self { alpha_per_m, p_min: range_gate_threshold(m), m: *m, medium, mode: ReturnMode::Strongest }
    }

    /// This weather for a sensor reporting in `mode` (module docs; [`SensorWeather::new`] gives
    /// `Strongest`).
    pub fn with_return_mode(self, mode: ReturnMode) -> Self {
        Self { mode, ..self }
    }

    /// The return mode the weather meets.
    pub fn return_mode(&self) -> ReturnMode {
        self.mode
    }

    /// The sensor's detection threshold (power units of the module docs).
    pub fn threshold(&self) -> f32 {
        self.p_min
    }

    /// The two-way transmission to `range_m`.
    pub fn transmission(&self, range_m: f32) -> f32 {
        (-2.0 * self.alpha_per_m * range_m).exp()
    }

    /// Decides a beam's nearest reported echo: `target` is its clear-weather return, `(range_m,
    /// intensity)`, or `None` when it returns nothing (the beam then meets the medium out to the
    /// maximum range). [`SensorWeather::echoes`]`.first`.
    pub fn beam(&self, target: Option<(f32, f32)>, key: &BeamKey) -> BeamOutcome {
        self.echoes(target, key).first
    }

    /// Decides a beam in the sensor's return mode (module docs): its nearest reported echo and,
    /// in `Dual`, the target's echo behind the medium's. `target` as in [`SensorWeather::beam`].
    pub fn echoes(&self, target: Option<(f32, f32)>, key: &BeamKey) -> BeamEchoes {
        self.echoes_with(target, key, None)
    }

    /// Per sensor column of the row `row` (`columns` of them): whether its beam is a candidate
    /// for a particle of rain or snow (drawn from the row's own stream with the chance of
    /// [`SensorWeather::candidate_chance`]; `out` is left empty in clear air and fog, where no
    /// beam needs one). [`SensorWeather::echoes_in_row`] decides a beam with its flag: most beams
    /// of a row then draw nothing, where each drew a uniform before (the scan's cost in rain and
    /// snow), and every beam holds a particle with the same chance as in
    /// [`SensorWeather::echoes`], which stays the reference.
    pub fn row_candidates(&self, row: &RowKey, columns: usize, out: &mut Vec<bool>) {
        out.clear();
        let Medium::Particles(table) = &self.medium else { return };
        out.resize(columns, false);
        let q = table.candidate_chance();
        if q >= 1.0 {
            out.fill(true);
            return;
        }
        if q <= 0.0 {
            return;
        }
        // Geometric gaps between candidates: floor(ln U / ln(1 - q)) beams skipped, U in (0, 1].
        let ln_keep = (-q).ln_1p();
        let mut rng = row.rng(Purpose::Weather);
        let mut c = 0usize;
        while c < columns {
            let u = 1.0 - rng.random::<f64>();
            let gap = (u.ln() / ln_keep).floor();
            if gap >= (columns - c) as f64 {
                break;
            }
            c += gap as usize;
            out[c] = true;
            c += 1;
        }
    }

    /// The chance with which [`SensorWeather::row_candidates`] draws a beam (0 in clear air and
    /// fog).
    pub fn candidate_chance(&self) -> f64 {
        match &self.medium {
            Medium::Particles(table) => table.candidate_chance(),
            _ => 0.0,
        }
    }

    /// [`SensorWeather::echoes`] for a beam of a row whose candidates
    /// [`SensorWeather::row_candidates`] drew: `candidate` is the beam's flag (ignored in clear air
    /// and fog). The same chances as [`SensorWeather::echoes`], other draws.
    pub fn echoes_in_row(&self, target: Option<(f32, f32)>, key: &BeamKey, candidate: bool) -> BeamEchoes {
        self.echoes_with(target, key, Some(candidate))
    }

    fn echoes_with(&self, target: Option<(f32, f32)>, key: &BeamKey, candidate: Option<bool>) -> BeamEchoes {
        let hard = target.map(|(r, i)| {
            let t2 = self.transmission(r);
            (r, i * t2, unsaturated_power(&self.m, i, r) * t2)
        });
        let hard = hard.filter(|&(_, _, p)| p >= self.p_min);
        let floor = match (self.mode, hard) {
            // The medium's return must be detectable and stronger than the target's.
            (ReturnMode::Strongest, _) => hard.map_or(self.p_min, |(_, _, p)| p.max(self.p_min)),
            // A detectable target is the last return: nothing in front of it is reported.
            (ReturnMode::Last, Some((_, intensity, _))) => {
                return BeamEchoes { first: BeamOutcome::Target { intensity }, target_behind: None };
            }
            // Detectable is enough: the target does not hide it.
            (ReturnMode::Last | ReturnMode::Dual, _) => self.p_min,
        };
        let reach_m = target.map_or(self.m.max_range_m, |(r, _)| r.min(self.m.max_range_m));
        let medium = match &self.medium {
            Medium::None => None,
            Medium::Fog(table) => table.strongest(reach_m, floor, key),
            Medium::Particles(table) => match candidate {
                None => table.strongest(reach_m, floor, key),
                Some(false) => None,
                Some(true) => table.strongest_candidate(reach_m, floor, key, table.candidate_chance()),
            },
        };
        // Quantised, the medium's return must still lie in front of the target.
        let medium = medium
            .map(|(range_m, power, class)| (quantise(range_m, self.m.range_quantum_m), power, class))
            .filter(|&(range_m, _, _)| target.is_none_or(|(r, _)| range_m < r));
        match (medium, hard) {
            (Some((range_m, power, class)), _) => BeamEchoes {
                first: BeamOutcome::Medium { range_m, intensity: saturate(&self.m, power, range_m), class },
                target_behind: hard.filter(|_| self.mode == ReturnMode::Dual).map(|(_, intensity, _)| intensity),
            },
            (None, Some((_, intensity, _))) => {
                BeamEchoes { first: BeamOutcome::Target { intensity }, target_behind: None }
            }
            (None, None) => BeamEchoes { first: BeamOutcome::Lost, target_behind: None },
        }
    }
}

/// The intensity model's value for an unsaturated power at `range_m`.
fn saturate(m: &Measurement, power: f32, range_m: f32) -> f32 {
    (power / (m.intensity_reference_m / range_m).powi(2).max(1.0)).clamp(0.0, 1.0)
}

fn quantise(range_m: f32, quantum_m: f32) -> f32 {
    if quantum_m > 0.0 { (range_m / quantum_m).round() * quantum_m } else { range_m }
}

/// A uniform draw in `[0, 1)` of the beam's weather stream, the `k`-th.
pub(crate) fn uniforms(key: &BeamKey) -> impl Iterator<Item = f32> {
    let mut rng = key.rng(Purpose::Weather);
    std::iter::repeat_with(move || rng.random::<f32>())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hdl() -> Measurement {
        crate::Rig::load("hdl64e-roof").unwrap().sensors[0].spec.measurement()
    }

    #[test]
    fn parse_and_refuse() {
        assert_eq!(Weather::parse("clear").unwrap(), Weather::Clear);
        assert_eq!(Weather::parse("rain:rate_mm_h=10").unwrap(), Weather::Rain { rate_mm_h: 10.0 });
        assert_eq!(Weather::parse("snow:rate_mm_h=2").unwrap().spec(), "snow:rate_mm_h=2");
        for (spec, needle) in [
            ("fog:visibility_m=0.5", "weather.visibility_m"),
            ("fog:visibility_m=-3", "1 ..= 100000"),
            ("fog:visibility_m=nan", "weather.visibility_m"),
            ("fog:visibility_m=inf", "weather.visibility_m"),
            ("rain:rate_mm_h=-1", "weather.rate_mm_h"),
            ("rain:rate_mm_h=60", "0 ..= 50 (rain is calibrated"),
            ("snow:rate_mm_h=50", "0 ..= 5 (snow is calibrated"),
            ("snow:rate_mm_h=5.5", "weather.rate_mm_h"),
            ("fog:rate_mm_h=3", "fog takes visibility_m"),
            ("fog", "fog:visibility_m=VALUE"),
            ("fog:visibility_m=x", "a number"),
            ("clear:visibility_m=3", "takes no fields"),
            ("sleet:rate_mm_h=1", "clear, fog, rain, snow"),
        ] {
            let e = Weather::parse(spec).unwrap_err().to_string();
            assert!(e.contains(needle), "{spec}: {e}");
        }
        let t: toml::Value = toml::from_str("kind = \"fog\"\nvisibility_m = 80.0\n").unwrap();
        assert_eq!(t.try_into::<Weather>().unwrap(), Weather::Fog { visibility_m: 80.0 });
        let t: toml::Value = toml::from_str("kind = \"fog\"\nvisibility = 80.0\n").unwrap();
        assert!(t.try_into::<Weather>().unwrap_err().to_string().contains("visibility"));
    }

    #[test]
    fn clear_keeps_bright_targets_and_loses_dim_ones_at_the_threshold() {
        let m = hdl();
        let w = SensorWeather::new(&Weather::Clear, &m);
        let key = BeamKey { seed: 1, frame: 0, sensor: 0, ring: 0, column: 0 };
        // P_min = 0.1 (12 / 120)^2 = 1e-3: a 10 % target at normal incidence at 120 m is right on it.
        assert!((w.threshold() - 1e-3).abs() < 1e-9);
        assert_eq!(
            w.beam(Some((50.0, 0.5 * (12.0f32 / 50.0).powi(2))), &key),
            BeamOutcome::Target { intensity: 0.5 * (12.0f32 / 50.0).powi(2) }
        );
        assert_eq!(w.beam(Some((100.0, 0.05 * (12.0f32 / 100.0).powi(2))), &key), BeamOutcome::Lost);
        assert_eq!(w.beam(None, &key), BeamOutcome::Lost);
    }

    /// Each sensor's threshold by its datasheet (docs/sensors.md, "Detection figures"): a target of
    /// the datasheet's reflectance at the datasheet's range is right on it, one a little dimmer or
    /// farther is below it; the weather's threshold is the range-gate rule, equal to it only for
    /// the Pandar64 (200 m at 10 %).
    #[test]
    fn datasheet_thresholds_put_the_datasheet_target_on_the_threshold() {
        let measurement = |rig: &str| crate::Rig::load(rig).unwrap().sensors[0].spec.measurement();
        // (rig, range m, reflectance): HDL-64E 50 m at 10 %, OS1 40 m at 10 %, Pandar64 200 m at
        // 10 %, PandarXT-32 80 m at 10 %, LUX 50 m at 10 %, the unstated Velodyne and Ouster
        // ranges at 80 %.
        for (rig, range_m, rho) in [
            ("hdl64e-roof", 50.0f32, 0.1f32),
            ("os1-128-roof", 40.0, 0.1),
            ("os1-64-roof", 40.0, 0.1),
            ("pandar64-roof", 200.0, 0.1),
            ("pandar-xt32-roof", 80.0, 0.1),
            ("lux-roof-4", 50.0, 0.1),
            ("vlp16-roof", 100.0, 0.8),
            ("hdl32e-roof", 100.0, 0.8),
            ("vls128-roof", 245.0, 0.8),
            ("os2-128-roof", 240.0, 0.8),
        ] {
            let m = measurement(rig);
            let p = detection_threshold(&m);
            let power = |rho: f32, r: f32| rho * (m.intensity_reference_m / r).powi(2);
            assert!((power(rho, range_m) / p - 1.0).abs() < 1e-5, "{rig}: {p} vs {}", power(rho, range_m));
            assert!(power(rho, 1.01 * range_m) < p && power(0.99 * rho, range_m) < p, "{rig}");
        }
        let pandar = measurement("pandar64-roof");
        assert_eq!(detection_threshold(&pandar), range_gate_threshold(&pandar));
        // The HDL-64E's datasheet threshold is (120 / 50)^2 = 5.76 times the range-gate rule's.
        let hdl = hdl();
        assert!((detection_threshold(&hdl) / range_gate_threshold(&hdl) - 5.76).abs() < 1e-4);
        assert_eq!(SensorWeather::new(&Weather::Snow { rate_mm_h: 1.0 }, &hdl).threshold(), range_gate_threshold(&hdl));
    }

    /// With fog, the largest range at which a target of reflectance `rho` is detected solves
    /// `rho (r_ref / R)^2 exp(-2 alpha R) = P_min`: checked against that root for three
    /// reflectances at visibility 200 m.
    #[test]
    fn fog_detection_range_follows_two_way_attenuation_and_the_threshold() {
        let m = hdl();
        let weather = Weather::Fog { visibility_m: 200.0 };
        let w = SensorWeather::new(&weather, &m);
        let alpha = weather.extinction_per_m();
        for rho in [0.1f64, 0.3, 0.9] {
            let p = |r: f64| rho * (12.0 / r).powi(2) * (-2.0 * alpha * r).exp() - f64::from(w.threshold());
            let (mut lo, mut hi) = (12.0, 200.0);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if p(mid) > 0.0 { lo = mid } else { hi = mid }
            }
            let root = lo as f32;
            let detected = |r: f32| {
                let key = BeamKey { seed: 9, frame: 0, sensor: 0, ring: 0, column: (r * 100.0) as u32 };
                let i = rho as f32 * (12.0 / r).powi(2).min(1.0);
                matches!(w.beam(Some((r, i)), &key), BeamOutcome::Target { .. })
            };
            assert!(detected(root - 0.05) && !detected(root + 0.05), "rho {rho}: root {root} m");
            // Far below the clear-weather range of the same target (clear: 120 m for rho 0.1).
            assert!(root < 12.0 * (rho as f32 / 1e-3).sqrt(), "rho {rho}: {root}");
        }
    }

    /// A bright wall behind snow: `Strongest` reports the wall (no flake outshines it), `Last` the
    /// wall, `Dual` the flake in front and the wall behind it wherever the beam holds a detectable
    /// flake. A dim far wall: `Strongest` reports whichever is stronger; `Last` still the wall.
    /// All modes draw the same strongest particle per beam key, so the modes are compared beam by
    /// beam.
    /// The row's candidates (`echoes_in_row`) and the beam on its own (`echoes`) give a particle
    /// with the same chance and at the same ranges: sky beams and beams with a target behind, in
    /// rain and snow (a dark wall at 60 m behind the flakes; a drop seldom beats even its echo), counted over
    /// 400,000 beams each way (different draws: the counts agree within 4 standard deviations of
    /// their difference).
    #[test]
    fn row_candidates_keep_every_beams_chance_of_a_particle() {
        let m = hdl();
        let wall = Some((60.0f32, 0.08f32 * (12.0f32 / 60.0).powi(2)));
        for (weather, target) in [
            (Weather::Rain { rate_mm_h: 50.0 }, None),
            (Weather::Snow { rate_mm_h: 3.0 }, None),
            (Weather::Snow { rate_mm_h: 3.0 }, wall),
        ] {
            let w = SensorWeather::new(&weather, &m);
            let q = w.candidate_chance();
            assert!(q > 0.0 && q < 1.0, "{weather:?}: {q}");
            {
                let (rows, columns) = (200u32, 2000usize);
                let (mut own, mut in_row) = (Vec::new(), Vec::new());
                let mut candidates = Vec::new();
                for ring in 0..rows {
                    let row = RowKey { seed: 11, frame: 0, sensor: 0, ring };
                    w.row_candidates(&row, columns, &mut candidates);
                    assert_eq!(candidates.len(), columns);
                    for (column, &candidate) in candidates.iter().enumerate() {
                        let key = BeamKey { seed: 11, frame: 0, sensor: 0, ring, column: column as u32 };
                        for (out, e) in [
                            (&mut own, w.echoes(target, &key)),
                            (&mut in_row, w.echoes_in_row(target, &key, candidate)),
                        ] {
                            if let BeamOutcome::Medium { range_m, .. } = e.first {
                                out.push(range_m);
                            }
                        }
                    }
                }
                let (a, b) = (own.len() as f64, in_row.len() as f64);
                assert!(a > 200.0, "{weather:?} {target:?}: {a} particles");
                assert!((a - b).abs() < 4.0 * (a + b).sqrt(), "{weather:?} {target:?}: {a} on their own, {b} in rows");
                let median = |v: &mut Vec<f32>| {
                    v.sort_by(f32::total_cmp);
                    v[v.len() / 2]
                };
                let (ma, mb) = (median(&mut own), median(&mut in_row));
                assert!(
                    (ma - mb).abs() < 0.1 * ma,
                    "{weather:?} {target:?}: median {ma} m on their own, {mb} m in rows"
                );
            }
        }
    }

    #[test]
    fn a_flake_in_front_of_a_wall_per_return_mode() {
        let m = hdl();
        let snow = Weather::Snow { rate_mm_h: 5.0 };
        let mode = |mode| SensorWeather::new(&snow, &m).with_return_mode(mode);
        let (strongest, last, dual) = (mode(ReturnMode::Strongest), mode(ReturnMode::Last), mode(ReturnMode::Dual));
        assert_eq!(SensorWeather::new(&snow, &m).return_mode(), ReturnMode::Strongest);
        // (range m, reflectance): a white wall at 15 m, a dark one at 60 m.
        for (wall_m, rho) in [(15.0f32, 0.9f32), (60.0, 0.08)] {
            let intensity = rho * (12.0 / wall_m).powi(2).min(1.0);
            let wall = Some((wall_m, intensity));
            let t2 = dual.transmission(wall_m);
            let p_wall = unsaturated_power(&m, intensity, wall_m) * t2;
            assert!(p_wall > dual.threshold(), "the wall is detectable");
            let attenuated = BeamOutcome::Target { intensity: intensity * t2 };
            let (mut flakes, mut flakes_win) = (0, 0);
            for column in 0..20_000 {
                let key = BeamKey { seed: 4, frame: 2, sensor: 0, ring: 7, column };
                let (s, l, d) = (strongest.echoes(wall, &key), last.echoes(wall, &key), dual.echoes(wall, &key));
                assert_eq!(l, BeamEchoes { first: attenuated, target_behind: None }, "last: the wall, always");
                match d.first {
                    BeamOutcome::Medium { range_m, intensity: flake, class } => {
                        flakes += 1;
                        assert_eq!(class, SemanticClass::SNOW);
                        assert!(range_m < wall_m, "the flake lies in front: {range_m}");
                        assert_eq!(d.target_behind, Some(intensity * t2), "dual: the wall behind the flake");
                        let p_flake = unsaturated_power(&m, flake, range_m);
                        if (p_flake / p_wall - 1.0).abs() < 1e-3 {
                            continue; // a tie within rounding
                        }
                        if p_flake > p_wall {
                            flakes_win += 1;
                            assert_eq!(s, BeamEchoes { first: d.first, target_behind: None }, "strongest: the flake");
                        } else {
                            assert_eq!(s.first, attenuated, "strongest: the wall ({p_flake} < {p_wall})");
                        }
                    }
                    other => {
                        assert_eq!(other, attenuated);
                        assert_eq!((d.target_behind, s.first), (None, attenuated), "no flake: the wall");
                    }
                }
            }
            eprintln!("wall {wall_m} m, rho {rho}: {flakes} flakes in front, {flakes_win} outshine it");
            assert!(flakes > 100, "wall {wall_m} m: {flakes} beams of 20000 with a flake");
            if wall_m < 20.0 {
                assert_eq!(flakes_win, 0, "no flake outshines a white wall at {wall_m} m");
            } else {
                assert!(flakes_win > 10 && flakes_win < flakes, "{flakes_win} of {flakes} outshine the dark wall");
            }
        }
        // Without a target (sky) every mode reports the same strongest flake, nothing behind it.
        for column in 0..2_000 {
            let key = BeamKey { seed: 4, frame: 2, sensor: 0, ring: 7, column };
            let s = strongest.echoes(None, &key);
            assert_eq!(s.target_behind, None);
            assert_eq!(last.echoes(None, &key), s);
            assert_eq!(dual.echoes(None, &key), s);
        }
    }

    /// A catalogued model meets the weather in its `return_mode`; the other models in `Strongest`,
    /// or in `Dual` (every echo, nearest first) when they report several echoes (the LUX).
    #[test]
    fn the_return_mode_comes_from_the_sensor() {
        let mode = |spec: &SensorSpec| return_mode_of(spec, &spec.measurement());
        let mut pandar = SensorSpec::default_for("pandar64").unwrap();
        assert_eq!(mode(&pandar), ReturnMode::Strongest);
        for want in [ReturnMode::Last, ReturnMode::Dual] {
            if let SensorSpec::Pandar64(c) = &mut pandar {
                c.return_mode = Some(want);
            }
            assert_eq!(mode(&pandar), want);
        }
        assert_eq!(mode(&SensorSpec::default_for("ibeo-lux").unwrap()), ReturnMode::Dual);
        for model in ["vlp16", "hdl64e", "os1-128", "utm30lx", "custom"] {
            assert_eq!(mode(&SensorSpec::default_for(model).unwrap()), ReturnMode::Strongest, "{model}");
        }
    }
}
