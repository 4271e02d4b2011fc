//! The shared machinery of spinning sensors (VLP-16, HDL-64E, OS1, custom): turning a table of
//! lasers into a destaggered rows x columns [`ScanPattern`].
//!
//! # Rotation, columns and time
//! The head turns clockwise seen from above (azimuth decreasing with time) at `f` revolutions per
//! second. A revolution holds exactly `cols` firing cycles of `period / cols` each: where the real
//! firing cycle does not divide the revolution (VLP-16: 55.296 us, 1808.45 cycles at 10 Hz), the
//! column count is rounded to the nearest integer and the cycle is stretched to `period / cols`
//! (VLP-16 at 10 Hz: 55.310 us, +0.025 %); the spacing of lasers inside a cycle is kept exact.
//! The frame starts with the encoder at azimuth +180 deg (pointing backwards), so the encoder
//! azimuth of firing cycle `k` at time `t` inside it is `pi - step * (k + t / cycle)`,
//! `step = 2 pi / cols`.
//!
//! # Destaggering
//! A laser with azimuth offset `delta` (positive to the left) fired `tau` after its cycle start
//! points at `a = pi - step * (k + u)` with `u = tau / cycle - delta / step`. Column `c` is an
//! azimuth bin centred on `pi - step * (c + phase)`, where `phase` is the mean of `u` over the
//! lasers reduced to `-0.5 ..= 0.5` (0 for the OS1 gen1 stagger, about 0.31 for the VLP-16 firing
//! sequence), so column 0 is centred within half a column of +180 deg. The firing of
//! a laser placed in column `c` is the one whose beam azimuth falls in that bin: cycle
//! `k = c - round(u - phase)`, taken modulo `cols` so that its time lies inside the frame
//! (`time_s = ((k mod cols) * cycle + tau) mod period`). Its direction uses the true beam azimuth, which lies
//! within half a column of the bin centre, and the exact table elevation. Neighbouring cells of the
//! grid are therefore neighbouring beams in space even when a sensor's lasers are staggered in
//! azimuth by many columns (HDL-64E: -8.5 .. +9.9 deg = about -49 .. +57 columns at 10 Hz).
//!
//! # Beam origins
//! Each laser may have an origin offset in the spinning head's frame (x along the beam's azimuth,
//! y to its left, z up). The offset turns with the head: `origin_in_sensor = Rz(a) * offset`.

use std::f64::consts::PI;

use glam::Vec3;

use super::{Firing, ScanPattern};

/// One laser of a spinning sensor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Laser {
    /// Elevation of the beam, radians (positive up).
    pub elevation_rad: f64,
    /// Azimuth offset of the beam from the encoder angle, radians (positive to the left).
    pub azimuth_offset_rad: f64,
    /// Beam origin in the head frame (x along the beam azimuth, y left, z up), metres.
    pub origin_in_head_m: [f64; 3],
    /// Firing time after the start of its firing cycle, seconds.
    pub time_offset_s: f64,
}

/// Builds the destaggered pattern of `lasers` (sorted by increasing elevation: row `i` is
/// `lasers[i]`) over `cols` columns at `frequency_hz` revolutions per second.
///
/// Invalid inputs (no lasers, zero columns, non-positive frequency) give an empty pattern; the
/// models validate their parameters before this is called.
pub fn spinning_pattern(lasers: &[Laser], cols: usize, frequency_hz: f64) -> ScanPattern {
    let rows = lasers.len();
    if rows == 0 || cols == 0 || !(frequency_hz.is_finite() && frequency_hz > 0.0) {
        return ScanPattern {
            rows: 0,
            cols: 0,
            firings: Vec::new(),
            row_elevation_rad: Vec::new(),
            col_azimuth_rad: Vec::new(),
            frame_period_s: 0.0,
        };
    }
    let period_s = 1.0 / frequency_hz;
    let cycle_s = period_s / cols as f64;
    let step_rad = 2.0 * PI / cols as f64;
    let us: Vec<f64> = lasers.iter().map(|l| l.time_offset_s / cycle_s - l.azimuth_offset_rad / step_rad).collect();
    let mean_u = us.iter().sum::<f64>() / rows as f64;
    let phase = mean_u - mean_u.round();

    // Lasers sharing a fractional column offset (all of an OS1-128, pairs of an HDL-64E) share
    // their per-column azimuths: compute each table of sines and cosines once.
    let mut tables: Vec<(u64, Vec<(f64, f64)>)> = Vec::new();
    let mut firings = Vec::with_capacity(rows * cols);
    for (laser, &u) in lasers.iter().zip(&us) {
        let shift = (u - phase).round() as i64;
        let offset = u - shift as f64;
        let key = offset.to_bits();
        let table_index = match tables.iter().position(|(k, _)| *k == key) {
            Some(i) => i,
            None => {
                let table = (0..cols).map(|c| (PI - step_rad * (c as f64 + offset)).sin_cos()).collect();
                tables.push((key, table));
                tables.len() - 1
            }
        };
        let trig = &tables[table_index].1;
        let (sin_el, cos_el) = laser.elevation_rad.sin_cos();
        let [ox, oy, oz] = laser.origin_in_head_m;
        let has_origin = ox != 0.0 || oy != 0.0 || oz != 0.0;
        for (c, &(sin_az, cos_az)) in trig.iter().enumerate() {
            // Beam azimuth = pi - step * (k + u) with k = c - shift: the table entry of column c.
            let k_wrapped = (c as i64 - shift).rem_euclid(cols as i64);
            // A time offset longer than a cycle pushes late firings past the frame end: they are
            // the same beams one revolution earlier.
            let t = (k_wrapped as f64 * cycle_s + laser.time_offset_s).rem_euclid(period_s);
            let time_s = if t < period_s { t } else { 0.0 };
            let dir = Vec3::new((cos_el * cos_az) as f32, (cos_el * sin_az) as f32, sin_el as f32);
            let origin = if has_origin {
                Vec3::new((ox * cos_az - oy * sin_az) as f32, (ox * sin_az + oy * cos_az) as f32, oz as f32)
            } else {
                Vec3::ZERO
            };
            firings.push(Some(Firing { origin_in_sensor: origin, dir_in_sensor: dir, time_s }));
        }
    }
    ScanPattern {
        rows,
        cols,
        firings,
        row_elevation_rad: lasers.iter().map(|l| l.elevation_rad as f32).collect(),
        col_azimuth_rad: (0..cols).map(|c| bin_centre_rad(c, step_rad, phase)).collect(),
        frame_period_s: period_s,
    }
}

/// Nominal azimuth of column `c`: `pi - step * (c + phase)`, not wrapped, so it decreases strictly
/// from about +pi to about -pi.
fn bin_centre_rad(c: usize, step_rad: f64, phase: f64) -> f32 {
    (PI - step_rad * (c as f64 + phase)) as f32
}

/// Columns of a spinning sensor whose firing cycle is `cycle_s` at `frequency_hz`: the number of
/// cycles per revolution rounded to the nearest integer (VLP-16 at 10 Hz: 1808; HDL-64E: 2083).
pub fn columns_per_revolution(cycle_s: f64, frequency_hz: f64) -> usize {
    (1.0 / (cycle_s * frequency_hz)).round().max(1.0) as usize
}
