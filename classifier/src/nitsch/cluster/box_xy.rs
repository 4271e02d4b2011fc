//! A growing x-y bounding box whose update is one `minps` and one `maxps` on x86-64.
//!
//! The clustering's last pass grows each cluster's box member by member, a chain of dependent
//! updates. Written with `Vec2::min` / `max` (or selects), LLVM packed the box into one register
//! and updated it with two compares, two mask moves, a blend and a masked move: about 10 cycles of
//! latency per member on the chain, most of that pass's time. Here the low and high corners are
//! two registers updated by `minps` / `maxps` (4 cycles each, side by side). For finite
//! coordinates the box is the same (`minps` may keep the other zero of a `-0.0` / `0.0` pair:
//! the same value).

use glam::Vec2;

#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::{__m128, _mm_cvtss_f32, _mm_max_ps, _mm_min_ps, _mm_setr_ps, _mm_shuffle_ps};

/// A box as its low and high corners (x in lane 0, y in lane 1).
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy)]
pub(super) struct BoxXy {
    lo: __m128,
    hi: __m128,
}

#[cfg(target_arch = "x86_64")]
impl BoxXy {
    /// The box of one point.
    #[inline(always)]
    pub(super) fn new(xy: Vec2) -> Self {
        let v = lanes(xy);
        Self { lo: v, hi: v }
    }

    /// The box from its corners.
    #[inline(always)]
    pub(super) fn from_corners((lo, hi): (Vec2, Vec2)) -> Self {
        Self { lo: lanes(lo), hi: lanes(hi) }
    }

    /// Grows the box to hold `xy` (`minps(xy, lo)`: `xy < lo ? xy : lo` per lane).
    #[inline(always)]
    pub(super) fn grow(&mut self, xy: Vec2) {
        let v = lanes(xy);
        // SAFETY: SSE is part of the x86-64 baseline: every x86-64 CPU runs `minps` / `maxps`.
        #[allow(unsafe_code)]
        unsafe {
            (self.lo, self.hi) = (_mm_min_ps(v, self.lo), _mm_max_ps(v, self.hi));
        }
    }

    /// The low and high corners.
    #[inline(always)]
    pub(super) fn corners(self) -> (Vec2, Vec2) {
        // SAFETY: SSE is part of the x86-64 baseline.
        #[allow(unsafe_code)]
        let lane = |v: __m128| unsafe { Vec2::new(_mm_cvtss_f32(v), _mm_cvtss_f32(_mm_shuffle_ps::<1>(v, v))) };
        (lane(self.lo), lane(self.hi))
    }
}

/// `xy` in lanes 0 and 1 of a register (zeros above).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn lanes(xy: Vec2) -> __m128 {
    // SAFETY: SSE is part of the x86-64 baseline.
    #[allow(unsafe_code)]
    unsafe {
        _mm_setr_ps(xy.x, xy.y, 0.0, 0.0)
    }
}

/// A box as its low and high corners (other architectures: `Vec2` selects).
#[cfg(not(target_arch = "x86_64"))]
#[derive(Clone, Copy)]
pub(super) struct BoxXy {
    lo: Vec2,
    hi: Vec2,
}

#[cfg(not(target_arch = "x86_64"))]
impl BoxXy {
    /// The box of one point.
    #[inline(always)]
    pub(super) fn new(xy: Vec2) -> Self {
        Self { lo: xy, hi: xy }
    }

    /// The box from its corners.
    #[inline(always)]
    pub(super) fn from_corners((lo, hi): (Vec2, Vec2)) -> Self {
        Self { lo, hi }
    }

    /// Grows the box to hold `xy`.
    #[inline(always)]
    pub(super) fn grow(&mut self, xy: Vec2) {
        (self.lo, self.hi) =
            (Vec2::select(xy.cmplt(self.lo), xy, self.lo), Vec2::select(xy.cmpgt(self.hi), xy, self.hi));
    }

    /// The low and high corners.
    #[inline(always)]
    pub(super) fn corners(self) -> (Vec2, Vec2) {
        (self.lo, self.hi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grows_to_the_points_min_and_max() {
        let pts = [Vec2::new(3.0, -1.0), Vec2::new(-2.5, 4.0), Vec2::new(1.0, 7.5), Vec2::new(0.0, -3.25)];
        let mut b = BoxXy::new(pts[0]);
        for &p in &pts[1..] {
            b.grow(p);
        }
        assert_eq!(b.corners(), (Vec2::new(-2.5, -3.25), Vec2::new(3.0, 7.5)));
        let mut c = BoxXy::from_corners(b.corners());
        c.grow(Vec2::new(10.0, -10.0));
        assert_eq!(c.corners(), (Vec2::new(-2.5, -10.0), Vec2::new(10.0, 7.5)));
    }
}
