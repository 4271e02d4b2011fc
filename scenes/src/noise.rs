//! Smooth, seeded 2-D value noise for uneven terrain.
//!
//! Lattice values come from a counter-based hash of (seed, ix, iy), so the noise is a pure function
//! of its inputs (no tables, no thread-order dependence); between lattice points it is blended
//! with the quintic smoothstep, which makes it C2-smooth. [`Fbm`] sums a few octaves.

/// SplitMix64 finaliser: a good 64-bit mixing function.
fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Lattice value in `[-1, 1]` at integer point `(ix, iy)`.
fn lattice(seed: u64, ix: i64, iy: i64) -> f32 {
    let h = mix64(seed ^ mix64((ix as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ (iy as u64).rotate_left(32)));
    ((h >> 40) as f32 / (1u64 << 24) as f32) * 2.0 - 1.0
}

fn smooth(t: f32) -> f32 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

/// Value noise in `[-1, 1]` with unit lattice spacing.
pub fn value_noise(seed: u64, x: f32, y: f32) -> f32 {
    let (fx, fy) = (x.floor(), y.floor());
    let (ix, iy) = (fx as i64, fy as i64);
    let (tx, ty) = (smooth(x - fx), smooth(y - fy));
    let a = lattice(seed, ix, iy);
    let b = lattice(seed, ix + 1, iy);
    let c = lattice(seed, ix, iy + 1);
    let d = lattice(seed, ix + 1, iy + 1);
    let ab = a + (b - a) * tx;
    let cd = c + (d - c) * tx;
    ab + (cd - ab) * ty
}

/// Fractal sum of value noise: `octaves` layers, each with half the wavelength and half the amplitude.
#[derive(Clone, Copy, Debug)]
pub struct Fbm {
    /// Seed of the lattice values.
    pub seed: u64,
    /// Wavelength of the first octave, metres.
    pub wavelength_m: f32,
    /// Peak amplitude of the sum, metres (the sum is normalised to `[-amplitude, amplitude]`).
    pub amplitude_m: f32,
    /// Number of octaves.
    pub octaves: u32,
}

impl Fbm {
    /// Height of the noise field at `(x, y)`, metres.
    pub fn at(&self, x: f32, y: f32) -> f32 {
        let (mut sum, mut norm, mut amp, mut freq) = (0.0, 0.0, 1.0, 1.0 / self.wavelength_m);
        for o in 0..self.octaves {
            sum += amp * value_noise(self.seed.wrapping_add(u64::from(o) * 0x632b_e59b), x * freq, y * freq);
            norm += amp;
            amp *= 0.5;
            freq *= 2.0;
        }
        self.amplitude_m * sum / norm.max(1e-6)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn noise_is_bounded_deterministic_and_continuous() {
        let f = Fbm { seed: 7, wavelength_m: 20.0, amplitude_m: 0.5, octaves: 3 };
        let mut max_step = 0.0f32;
        for i in 0..2000 {
            let x = i as f32 * 0.05 - 50.0;
            let h = f.at(x, 3.3);
            assert!(h.abs() <= 0.5 + 1e-6);
            assert_eq!(h, f.at(x, 3.3));
            max_step = max_step.max((f.at(x + 0.05, 3.3) - h).abs());
        }
        // Smooth: a 5 cm step never changes the height by more than a few cm.
        assert!(max_step < 0.03, "max step {max_step}");
        let g = Fbm { seed: 8, ..f };
        assert_ne!(f.at(1.5, 2.5), g.at(1.5, 2.5));
    }
}
