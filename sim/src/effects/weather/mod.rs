//! Weather per beam: fog, rain and snow decided for every beam as the scan measures it, before a
//! return is chosen, seeded like the rest of the noise (keyed by seed, frame, sensor, ring,
//! column: thread counts cannot change a scan).
//!
//! A sensor in weather measures power, not just distance. In the units of the intensity model
//! ([`crate::effects::measure`]) a return of reflectance `rho cos(theta)` at range `R` has the
//! power `P = rho cos(theta) (r_ref / R)^2` (unsaturated), and the sensor detects it when
//! `P >= P_min`, its detection threshold: `P_min = 0.1 (r_ref / max_range)^2`, a 10 % target at
//! normal incidence seen out to the sensor's maximum range in clear air. The medium attenuates a
//! hard target twice (out and back), `T^2 = exp(-2 alpha R)`, and adds returns of its own; the
//! sensor reports the strongest detectable return of the beam, as single-return units do:
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
//!   on WADS's labelled snowfall and accepted up to [`SNOW_CALIBRATED_MAX_MM_H`].
//!
//! `clear` applies the detection threshold without a medium: the reference a weather scan is
//! compared with. Returns from the medium get their own classes ([`SemanticClass::FOG`],
//! [`SemanticClass::RAIN`], [`SemanticClass::SNOW`]); every other return keeps its ground truth,
//! its intensity reduced by `T^2`. Later echoes of multi-echo sensors are left as they are.

pub mod fog;
pub mod particles;

use std::sync::Arc;

use rand::RngExt;
use serde::{Deserialize, Serialize};

use crate::error::{Result, SimError};
use crate::noise::{BeamKey, Purpose};
use crate::scene::SemanticClass;
use crate::sensor::Measurement;

/// The largest snowfall rate accepted, mm/h of water: the calibrated range (docs/weather.md). A
/// larger rate is refused, naming this range.
pub const SNOW_CALIBRATED_MAX_MM_H: f64 = 5.0;

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
    /// Rain of the given rate (mm/h, 0 ..= 200).
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
            Weather::Rain { rate_mm_h } => check("rate_mm_h", rate_mm_h, 0.0, 200.0),
            Weather::Snow { rate_mm_h } => {
                if rate_mm_h.is_finite() && (0.0..=SNOW_CALIBRATED_MAX_MM_H).contains(&rate_mm_h) {
                    Ok(())
                } else {
                    Err(SimError::invalid(
                        "weather.rate_mm_h",
                        rate_mm_h,
                        format!(
                            "0 ..= {SNOW_CALIBRATED_MAX_MM_H} (snow is calibrated on measured snowfall up to \
                             {SNOW_CALIBRATED_MAX_MM_H} mm/h of water; docs/weather.md)"
                        ),
                    ))
                }
            }
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

/// The detection threshold of a sensor in the intensity model's power units:
/// `0.1 (r_ref / max_range)^2` (module docs).
pub fn detection_threshold(m: &Measurement) -> f32 {
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

/// The medium as one sensor sees it.
#[derive(Clone, Debug)]
enum Medium {
    None,
    Fog(Arc<fog::FogTable>),
    Particles(Arc<particles::ParticleTable>),
}

/// The weather for one sensor: its threshold, the medium's extinction and the tables of its own
/// returns, built once per scan.
#[derive(Clone, Debug)]
pub struct SensorWeather {
    alpha_per_m: f32,
    p_min: f32,
    m: Measurement,
    medium: Medium,
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
        Self { alpha_per_m, p_min: detection_threshold(m), m: *m, medium }
    }

    /// The sensor's detection threshold (power units of the module docs).
    pub fn threshold(&self) -> f32 {
        self.p_min
    }

    /// The two-way transmission to `range_m`.
    pub fn transmission(&self, range_m: f32) -> f32 {
        (-2.0 * self.alpha_per_m * range_m).exp()
    }

    /// Decides a beam: `target` is its clear-weather return, `(range_m, intensity)`, or `None`
    /// when it returns nothing (the beam then meets the medium out to the maximum range).
    pub fn beam(&self, target: Option<(f32, f32)>, key: &BeamKey) -> BeamOutcome {
        let hard = target.map(|(r, i)| {
            let t2 = self.transmission(r);
            (r, i * t2, unsaturated_power(&self.m, i, r) * t2)
        });
        let hard = hard.filter(|&(_, _, p)| p >= self.p_min);
        // The medium's return must be detectable and stronger than the target's.
        let floor = hard.map_or(self.p_min, |(_, _, p)| p.max(self.p_min));
        let reach_m = target.map_or(self.m.max_range_m, |(r, _)| r.min(self.m.max_range_m));
        let medium = match &self.medium {
            Medium::None => None,
            Medium::Fog(table) => table.strongest(reach_m, floor, key),
            Medium::Particles(table) => table.strongest(reach_m, floor, key),
        };
        // Quantised, the medium's return must still lie in front of the target.
        let medium = medium
            .map(|(range_m, power, class)| (quantise(range_m, self.m.range_quantum_m), power, class))
            .filter(|&(range_m, _, _)| target.is_none_or(|(r, _)| range_m < r));
        match (medium, hard) {
            (Some((range_m, power, class)), _) => {
                BeamOutcome::Medium { range_m, intensity: saturate(&self.m, power, range_m), class }
            }
            (None, Some((_, intensity, _))) => BeamOutcome::Target { intensity },
            (None, None) => BeamOutcome::Lost,
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
}
