//! What ordering reads from an input point: packed `Vec3`s, or the 16-byte records of a KITTI
//! `.bin` (`x y z intensity`, float32) read where the file's bytes lie.
//!
//! Reading the records in place saves decoding them into points and intensities first, a copy
//! of the whole frame: measured with `bench classify` on KITTI frames, one core (see
//! `docs/real-recordings-speed.md`, session 31).

use glam::Vec3;

/// A point as ordering reads it: its coordinates (sensor frame, metres) and, where it carries
/// one, its intensity.
///
/// ```
/// use classifier::ordering::InputPoint;
/// let record = [1.0f32, 2.0, 3.0, 0.25];
/// assert_eq!(record.xyz(), glam::Vec3::new(1.0, 2.0, 3.0));
/// assert_eq!(record.intensity(), Some(0.25));
/// assert_eq!(glam::Vec3::ONE.intensity(), None);
/// ```
pub trait InputPoint: Copy + Send + Sync + 'static {
    /// Whether [`InputPoint::intensity`] gives a value.
    const HAS_INTENSITY: bool;

    /// The coordinates, metres.
    fn xyz(self) -> Vec3;

    /// The intensity the point carries, if any (used where the attributes give none).
    fn intensity(self) -> Option<f32>;
}

impl InputPoint for Vec3 {
    const HAS_INTENSITY: bool = false;

    #[inline(always)]
    fn xyz(self) -> Vec3 {
        self
    }

    #[inline(always)]
    fn intensity(self) -> Option<f32> {
        None
    }
}

/// A KITTI `.bin` record: `x y z intensity`.
impl InputPoint for [f32; 4] {
    const HAS_INTENSITY: bool = true;

    #[inline(always)]
    fn xyz(self) -> Vec3 {
        Vec3::new(self[0], self[1], self[2])
    }

    #[inline(always)]
    fn intensity(self) -> Option<f32> {
        Some(self[3])
    }
}
