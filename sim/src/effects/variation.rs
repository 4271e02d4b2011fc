//! Variations applied to a finished frame, for datasets that randomise what real units vary beyond
//! the measurement model: random dropout of returns (dust on the window, dark surfaces, a unit
//! that loses more returns than its datasheet) and an intensity scale (another unit's calibration).
//! Each dropout draw is keyed by (seed, frame, sensor, ring, column) ([`crate::noise`]), so a frame
//! loses the same returns at any thread count.

use glam::Vec3;

use crate::OrderedCloud;
use crate::error::{Result, SimError};
use crate::noise::{BeamKey, Purpose};
use crate::scene::SemanticClass;

/// Removes each return of `cloud` with probability `probability` (`0 ..= 1`), drawn from the
/// stream of its (seed, frame, sensor, ring, column); the cell becomes a no-return cell. Returns
/// how many were removed.
///
/// ```
/// let mut cloud = sim::OrderedCloud::empty(1, 1000, 1);
/// for p in cloud.point_in_vehicle.iter_mut() { *p = glam::Vec3::X; }
/// cloud.range_m.fill(1.0);
/// for (c, col) in cloud.column.iter_mut().enumerate() { *col = c as u32; }
/// cloud.sensor.fill(0);
/// let removed = sim::effects::variation::drop_returns(&mut cloud, 0.1, 7, 0).unwrap();
/// assert!((60..140).contains(&removed), "{removed}");
/// assert_eq!(cloud.returns(), 1000 - removed);
/// ```
pub fn drop_returns(cloud: &mut OrderedCloud, probability: f32, seed: u64, frame: u32) -> Result<usize> {
    use rand::RngExt;
    if !(probability.is_finite() && (0.0..=1.0).contains(&probability)) {
        return Err(SimError::invalid("dropout", probability, "0 ..= 1"));
    }
    if probability == 0.0 {
        return Ok(0);
    }
    let mut removed = 0;
    for i in 0..cloud.len() {
        if !cloud.point_in_vehicle[i].is_finite() {
            continue;
        }
        // The echo plane in the key's column bits, so the echoes of one beam draw apart.
        let plane = (i / (cloud.rows * cloud.cols).max(1)) as u32;
        let key = BeamKey {
            seed,
            frame,
            sensor: u32::from(cloud.sensor[i]),
            ring: u32::from(cloud.ring[i]),
            column: cloud.column[i] | (plane << 24),
        };
        if key.rng(Purpose::Dropout).random::<f32>() < probability {
            cloud.point_in_vehicle[i] = Vec3::NAN;
            cloud.range_m[i] = f32::NAN;
            cloud.intensity[i] = 0.0;
            cloud.echo[i] = 0;
            cloud.label[i] = SemanticClass::UNLABELED;
            cloud.instance[i] = 0;
            cloud.ground[i] = false;
            cloud.normal[i] = Vec3::ZERO;
            removed += 1;
        }
    }
    Ok(removed)
}

/// Multiplies every intensity by `scale` (`0 ..= 10`), clamped to `[0, 1]`.
///
/// ```
/// let mut cloud = sim::OrderedCloud::empty(1, 2, 1);
/// cloud.intensity.copy_from_slice(&[0.2, 0.8]);
/// sim::effects::variation::scale_intensity(&mut cloud, 1.5).unwrap();
/// assert_eq!(cloud.intensity, vec![0.3, 1.0]);
/// ```
pub fn scale_intensity(cloud: &mut OrderedCloud, scale: f32) -> Result<()> {
    if !(scale.is_finite() && (0.0..=10.0).contains(&scale)) {
        return Err(SimError::invalid("intensity_scale", scale, "0 ..= 10"));
    }
    for v in &mut cloud.intensity {
        *v = (*v * scale).clamp(0.0, 1.0);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cloud() -> OrderedCloud {
        let mut c = OrderedCloud::empty(4, 500, 1);
        for i in 0..c.len() {
            c.point_in_vehicle[i] = Vec3::new(1.0, 0.0, 0.0);
            c.range_m[i] = 1.0;
            c.ring[i] = (i / 500) as u16;
            c.column[i] = (i % 500) as u32;
            c.sensor[i] = 0;
            c.ground[i] = true;
        }
        c
    }

    #[test]
    fn dropout_is_keyed_and_has_its_rate() {
        let (mut a, mut b) = (cloud(), cloud());
        let n = drop_returns(&mut a, 0.25, 3, 1).unwrap();
        drop_returns(&mut b, 0.25, 3, 1).unwrap();
        let kept = |c: &OrderedCloud| c.point_in_vehicle.iter().map(|p| p.is_finite()).collect::<Vec<_>>();
        assert!(kept(&a) == kept(&b), "the same returns removed for the same keys");
        assert!((400..600).contains(&n), "{n} of 2000");
        assert_eq!(a.returns(), 2000 - n);
        assert_eq!(a.ground_returns(), 2000 - n);
        let mut c = cloud();
        drop_returns(&mut c, 0.25, 3, 2).unwrap();
        assert!(kept(&c) != kept(&a), "another frame loses other returns");
        assert!(drop_returns(&mut cloud(), 1.5, 0, 0).unwrap_err().to_string().contains("dropout"));
        assert_eq!(drop_returns(&mut cloud(), 0.0, 0, 0).unwrap(), 0);
        assert!(scale_intensity(&mut cloud(), f32::NAN).unwrap_err().to_string().contains("intensity_scale"));
    }
}
