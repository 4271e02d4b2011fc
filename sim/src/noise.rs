//! Counter-based random streams: every random number of a scan is drawn from a generator keyed by
//! (seed, frame, sensor, ring, column, purpose), so results never depend on thread count or order.

use rand::{RngExt, SeedableRng};
use rand_distr::StandardNormal;
use rand_xoshiro::Xoshiro256PlusPlus;

/// What a random draw is for (keeps the streams of different effects independent).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Purpose {
    /// Gaussian range noise.
    RangeNoise = 1,
    /// Random dropout.
    Dropout = 2,
    /// Sub-beam sampling inside the beam divergence cone.
    Divergence = 3,
    /// Weather: particles in the beam, the range of a fog return.
    Weather = 4,
}

/// The key of one beam's stream.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BeamKey {
    /// The run's seed.
    pub seed: u64,
    /// Frame index.
    pub frame: u32,
    /// Sensor index in the rig.
    pub sensor: u32,
    /// Sensor ring.
    pub ring: u32,
    /// Sensor column.
    pub column: u32,
}

/// The key of one sensor row's stream: the noise of column `c` is the `c`-th draw of the stream of
/// (seed, frame, sensor, ring), drawn for every column whether it returns or not, so a value depends
/// on its (seed, frame, sensor, ring, column) alone.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RowKey {
    /// The run's seed.
    pub seed: u64,
    /// Frame index.
    pub frame: u32,
    /// Sensor index in the rig.
    pub sensor: u32,
    /// Sensor ring.
    pub ring: u32,
}

impl RowKey {
    /// The row's own stream for `purpose` (distinct from every beam's: column `u32::MAX` never
    /// occurs in a grid).
    pub fn rng(&self, purpose: Purpose) -> Xoshiro256PlusPlus {
        BeamKey { seed: self.seed, frame: self.frame, sensor: self.sensor, ring: self.ring, column: u32::MAX }
            .rng(purpose)
    }

    /// `columns` standard normal draws of this row for `purpose`, one per column.
    pub fn normals(&self, purpose: Purpose, columns: usize) -> Vec<f32> {
        let mut rng = self.rng(purpose);
        (0..columns).map(|_| rng.sample(StandardNormal)).collect()
    }
}

/// SplitMix64 finaliser: a bijective 64-bit mix.
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

impl BeamKey {
    /// A portable generator (Xoshiro256++) for this beam and purpose.
    pub fn rng(&self, purpose: Purpose) -> Xoshiro256PlusPlus {
        let mut h = mix(self.seed ^ 0x9e37_79b9_7f4a_7c15);
        for v in [self.frame, self.sensor, self.ring, self.column, purpose as u32] {
            h = mix(h ^ u64::from(v).wrapping_mul(0x9e37_79b9_7f4a_7c15));
        }
        Xoshiro256PlusPlus::seed_from_u64(h)
    }

    /// One standard normal draw for this beam and purpose (ziggurat, `rand_distr::StandardNormal`).
    pub fn normal(&self, purpose: Purpose) -> f32 {
        self.rng(purpose).sample(StandardNormal)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(column: u32) -> BeamKey {
        BeamKey { seed: 7, frame: 0, sensor: 0, ring: 3, column }
    }

    #[test]
    fn same_key_same_draw_and_different_keys_differ() {
        assert_eq!(key(5).normal(Purpose::RangeNoise), key(5).normal(Purpose::RangeNoise));
        assert_ne!(key(5).normal(Purpose::RangeNoise), key(6).normal(Purpose::RangeNoise));
        assert_ne!(key(5).normal(Purpose::RangeNoise), key(5).normal(Purpose::Dropout));
    }

    #[test]
    fn row_draws_are_fixed_per_column_and_have_unit_variance() {
        let row = RowKey { seed: 7, frame: 1, sensor: 0, ring: 3 };
        let a = row.normals(Purpose::RangeNoise, 20_000);
        assert_eq!(&row.normals(Purpose::RangeNoise, 10)[..], &a[..10], "a prefix does not depend on the length");
        assert_ne!(RowKey { ring: 4, ..row }.normals(Purpose::RangeNoise, 10), a[..10]);
        let mean = a.iter().map(|&x| f64::from(x)).sum::<f64>() / a.len() as f64;
        let var = a.iter().map(|&x| (f64::from(x) - mean).powi(2)).sum::<f64>() / a.len() as f64;
        assert!(mean.abs() < 0.03 && (var - 1.0).abs() < 0.05, "mean {mean} var {var}");
    }

    #[test]
    fn normal_draws_have_unit_variance() {
        let xs: Vec<f64> = (0..20_000).map(|c| f64::from(key(c).normal(Purpose::RangeNoise))).collect();
        let mean = xs.iter().sum::<f64>() / xs.len() as f64;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / xs.len() as f64;
        assert!(mean.abs() < 0.03, "mean {mean}");
        assert!((var - 1.0).abs() < 0.05, "variance {var}");
    }
}
