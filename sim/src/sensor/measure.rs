//! Per-sensor overrides of the range measurement model ([`Measurement`]) and its validation.
//!
//! Every sensor model has documented default measurement figures (see each model's
//! `default_measurement`). A sensor table may override any of them in a `[measurement]` sub-table,
//! e.g. `measurement = { range_sigma_m = 0.05, max_echoes = 2 }`; fields left out keep the model's
//! default.

use serde::{Deserialize, Serialize};

use super::Measurement;
use crate::error::{Result, SimError, check_range};

/// Optional overrides of a model's default [`Measurement`] (TOML: `[measurement]`, every field optional).
#[derive(Clone, Copy, Debug, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MeasurementParams {
    /// Override of [`Measurement::min_range_m`], metres.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub min_range_m: Option<f32>,
    /// Override of [`Measurement::max_range_m`], metres.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_range_m: Option<f32>,
    /// Override of [`Measurement::range_sigma_m`], metres.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub range_sigma_m: Option<f32>,
    /// Override of [`Measurement::range_quantum_m`], metres.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub range_quantum_m: Option<f32>,
    /// Override of [`Measurement::max_incidence_deg`], degrees.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_incidence_deg: Option<f32>,
    /// Override of [`Measurement::beam_divergence_rad`], radians.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub beam_divergence_rad: Option<f32>,
    /// Override of [`Measurement::max_echoes`].
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_echoes: Option<u8>,
    /// Override of [`Measurement::echo_separation_m`], metres.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub echo_separation_m: Option<f32>,
    /// Override of [`Measurement::intensity_reference_m`], metres.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub intensity_reference_m: Option<f32>,
    /// Override of [`Measurement::detection_range_m`], metres.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub detection_range_m: Option<f32>,
    /// Override of [`Measurement::detection_reflectance`], `(0, 1]`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub detection_reflectance: Option<f32>,
}

impl MeasurementParams {
    /// `base` with every override that is set applied.
    pub fn apply(&self, base: Measurement) -> Measurement {
        Measurement {
            min_range_m: self.min_range_m.unwrap_or(base.min_range_m),
            max_range_m: self.max_range_m.unwrap_or(base.max_range_m),
            range_sigma_m: self.range_sigma_m.unwrap_or(base.range_sigma_m),
            range_quantum_m: self.range_quantum_m.unwrap_or(base.range_quantum_m),
            max_incidence_deg: self.max_incidence_deg.unwrap_or(base.max_incidence_deg),
            beam_divergence_rad: self.beam_divergence_rad.unwrap_or(base.beam_divergence_rad),
            max_echoes: self.max_echoes.unwrap_or(base.max_echoes),
            echo_separation_m: self.echo_separation_m.unwrap_or(base.echo_separation_m),
            intensity_reference_m: self.intensity_reference_m.unwrap_or(base.intensity_reference_m),
            detection_range_m: self.detection_range_m.unwrap_or(base.detection_range_m),
            detection_reflectance: self.detection_reflectance.unwrap_or(base.detection_reflectance),
        }
    }
}

/// The reflectance a vendor's range is taken at when the vendor states none ("up to 100 m"): a
/// bright target, 80 %. Where a vendor quotes both, its headline range is the 80 % one: the
/// HDL-64E's 120 m (50 m at 10 %), the OS1's 120 m (40 m at 10 %); docs/sensors.md, "Detection
/// figures".
pub const UNSTATED_DETECTION_REFLECTANCE: f32 = 0.8;

/// Largest range any model accepts, metres.
pub const MAX_RANGE_LIMIT_M: f64 = 10_000.0;

/// Checks a resolved measurement model; `field` is the dotted prefix (e.g. `sensors[0].spec.measurement`).
pub fn validate_measurement(field: &str, m: &Measurement) -> Result<()> {
    let f = |name: &str| format!("{field}.{name}");
    check_range(&f("min_range_m"), m.min_range_m as f64, 0.0, 1_000.0)?;
    check_range(&f("max_range_m"), m.max_range_m as f64, 0.0, MAX_RANGE_LIMIT_M)?;
    if m.max_range_m <= m.min_range_m {
        return Err(SimError::invalid(
            f("max_range_m"),
            m.max_range_m,
            format!("greater than min_range_m = {} and <= {MAX_RANGE_LIMIT_M}", m.min_range_m),
        ));
    }
    check_range(&f("range_sigma_m"), m.range_sigma_m as f64, 0.0, 10.0)?;
    check_range(&f("range_quantum_m"), m.range_quantum_m as f64, 0.0, 10.0)?;
    if !(m.max_incidence_deg.is_finite() && m.max_incidence_deg > 0.0 && m.max_incidence_deg <= 90.0) {
        return Err(SimError::invalid(f("max_incidence_deg"), m.max_incidence_deg, "0 < x <= 90"));
    }
    check_range(&f("beam_divergence_rad"), m.beam_divergence_rad as f64, 0.0, 0.1)?;
    if !(1..=3).contains(&m.max_echoes) {
        return Err(SimError::invalid(f("max_echoes"), m.max_echoes, "1 ..= 3"));
    }
    check_range(&f("echo_separation_m"), m.echo_separation_m as f64, 0.0, 100.0)?;
    if !(m.intensity_reference_m.is_finite() && m.intensity_reference_m > 0.0 && m.intensity_reference_m <= 10_000.0) {
        return Err(SimError::invalid(f("intensity_reference_m"), m.intensity_reference_m, "0 < x <= 10000"));
    }
    if !(m.detection_range_m.is_finite()
        && m.detection_range_m > 0.0
        && f64::from(m.detection_range_m) <= MAX_RANGE_LIMIT_M)
    {
        return Err(SimError::invalid(
            f("detection_range_m"),
            m.detection_range_m,
            format!("0 < x <= {MAX_RANGE_LIMIT_M}"),
        ));
    }
    if !(m.detection_reflectance.is_finite() && m.detection_reflectance > 0.0 && m.detection_reflectance <= 1.0) {
        return Err(SimError::invalid(f("detection_reflectance"), m.detection_reflectance, "0 < x <= 1"));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The detection figure is overridable and checked: a range in `(0, 10000]` m, a reflectance
    /// in `(0, 1]`, each refused naming its field.
    #[test]
    fn the_detection_figure_is_overridden_and_checked() {
        let base = Measurement::spinning(0.5, 120.0, 0.01, 0.001).with_detection(40.0, 0.1);
        let params = MeasurementParams { detection_range_m: Some(45.0), ..Default::default() };
        let m = params.apply(base);
        assert_eq!((m.detection_range_m, m.detection_reflectance), (45.0, 0.1));
        assert!(validate_measurement("s", &m).is_ok());
        for (range_m, rho, field) in [
            (0.0, 0.1, "s.detection_range_m"),
            (f32::NAN, 0.1, "s.detection_range_m"),
            (20_000.0, 0.1, "s.detection_range_m"),
            (40.0, 0.0, "s.detection_reflectance"),
            (40.0, 1.5, "s.detection_reflectance"),
        ] {
            let e = validate_measurement("s", &base.with_detection(range_m, rho)).unwrap_err().to_string();
            assert!(e.contains(field), "{range_m} m at {rho}: {e}");
        }
        let toml: MeasurementParams = toml::from_str("detection_reflectance = 0.8").unwrap();
        assert_eq!(toml.apply(base).detection_reflectance, 0.8);
    }
}
