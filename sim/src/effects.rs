//! Measurement effects applied to a true intersection: grazing dropout, Gaussian range noise, range
//! quantisation, min / max range gates and intensity. Each effect is switched by its
//! [`Measurement`] field (see there for defaults); [`Measurement::ideal`] turns them all off.
//!
//! Intensity model (documented, simple and monotone): `I = clamp(rho * cos(theta) * min(1, (r_ref / r)^2), 0, 1)`
//! with `rho` the surface reflectivity, `theta` the incidence angle and `r_ref` the sensor's
//! `intensity_reference_m` (targets nearer than `r_ref` saturate the range term).

pub mod variation;
pub mod weather;

use crate::sensor::Measurement;

/// A measured return.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Measured {
    /// Reported range, metres.
    pub range_m: f32,
    /// Intensity in `[0, 1]`.
    pub intensity: f32,
}

/// Largest distance worth casting for a measurement model: the maximum range plus room for noise.
pub fn cast_limit_m(m: &Measurement) -> f32 {
    m.max_range_m + 5.0 * m.range_sigma_m + m.range_quantum_m
}

/// Turns a true hit (distance `true_range_m`, cosine of the incidence angle `cos_incidence`, surface
/// `reflectivity`) into a measured return, or `None` when the sensor would report nothing.
/// `standard_normal` is the beam's standard normal draw (see [`crate::noise`]).
pub fn measure(
    m: &Measurement,
    true_range_m: f32,
    cos_incidence: f32,
    reflectivity: f32,
    standard_normal: f32,
) -> Option<Measured> {
    let cos_incidence = cos_incidence.clamp(0.0, 1.0);
    if m.max_incidence_deg < 90.0 && cos_incidence < m.max_incidence_deg.to_radians().cos() {
        return None;
    }
    let mut range_m = true_range_m;
    if m.range_sigma_m > 0.0 {
        range_m += m.range_sigma_m * standard_normal;
    }
    if m.range_quantum_m > 0.0 {
        range_m = (range_m / m.range_quantum_m).round() * m.range_quantum_m;
    }
    if !(range_m >= m.min_range_m && range_m <= m.max_range_m) {
        return None;
    }
    let falloff = (m.intensity_reference_m / range_m).powi(2).min(1.0);
    let intensity = (reflectivity * cos_incidence * falloff).clamp(0.0, 1.0);
    Some(Measured { range_m, intensity })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lidar() -> Measurement {
        Measurement {
            min_range_m: 0.5,
            max_range_m: 100.0,
            range_sigma_m: 0.03,
            range_quantum_m: 0.01,
            max_incidence_deg: 85.0,
            beam_divergence_rad: 0.0,
            max_echoes: 1,
            echo_separation_m: 1.0,
            intensity_reference_m: 10.0,
            detection_range_m: 100.0,
            detection_reflectance: 0.1,
        }
    }

    fn key(c: u32) -> f32 {
        crate::noise::BeamKey { seed: 1, frame: 0, sensor: 0, ring: 0, column: c }
            .normal(crate::noise::Purpose::RangeNoise)
    }

    #[test]
    fn ideal_is_exact_and_gated() {
        let m = lidar().ideal();
        let r = measure(&m, 12.345_678, 1.0, 0.5, key(0)).unwrap();
        assert_eq!(r.range_m, 12.345_678);
        assert!((r.intensity - 0.5 * (10.0f32 / 12.345_678).powi(2)).abs() < 1e-6);
        assert!(measure(&m, 0.4, 1.0, 0.5, key(0)).is_none(), "below min range");
        assert!(measure(&m, 100.5, 1.0, 0.5, key(0)).is_none(), "beyond max range");
        assert!(measure(&m, 10.0, 0.01, 0.5, key(0)).is_some(), "ideal keeps grazing returns");
    }

    #[test]
    fn noise_has_the_sigma_and_quantisation_the_step() {
        let m = lidar();
        let ranges: Vec<f32> =
            (0..5000).filter_map(|c| measure(&m, 20.0, 1.0, 0.5, key(c))).map(|r| r.range_m).collect();
        assert_eq!(ranges.len(), 5000);
        for r in &ranges {
            let steps = r / 0.01;
            assert!((steps - steps.round()).abs() < 1e-3, "{r} is on the 1 cm grid");
        }
        let mean = ranges.iter().map(|&r| f64::from(r)).sum::<f64>() / 5000.0;
        let sd = (ranges.iter().map(|&r| (f64::from(r) - mean).powi(2)).sum::<f64>() / 5000.0).sqrt();
        assert!((mean - 20.0).abs() < 0.003, "mean {mean}");
        // sigma 3 cm plus uniform quantisation noise (1 cm / sqrt(12)).
        let expected = (0.03f64.powi(2) + 0.01f64.powi(2) / 12.0).sqrt();
        assert!((sd - expected).abs() < 0.002, "sd {sd} vs {expected}");
    }

    #[test]
    fn grazing_returns_drop_beyond_the_limit() {
        let m = lidar();
        assert!(measure(&m, 10.0, 86f32.to_radians().cos(), 0.5, key(0)).is_none());
        assert!(measure(&m, 10.0, 84f32.to_radians().cos(), 0.5, key(0)).is_some());
    }
}
