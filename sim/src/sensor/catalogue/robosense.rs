//! RoboSense RS-Helios 5515 (32 beams, +15 .. -55 deg).
//!
//! Table: `RobosenseHelios.csv` in tier4/nebula (`nebula_decoders/calibration/robosense/`, commit
//! c60082d5; one `elevation,azimuth` line per channel, degrees, channel order). RoboSense's
//! azimuth is clockwise (nebula's decoder puts a point at `x = d cos(a)`, `y = -d sin(a)`): sign
//! -1. Firing times and range limits: nebula's `decoders/helios.hpp` (commit 606ac41f, the first
//! row of its single-return `firing_time_offset_ns`; rs_driver's `decoder_RSHELIOS.hpp` spaces
//! the channels evenly by 1.73 us instead). Lens centre 34.98 mm from the spin axis (rs_driver's
//! `RX`). Rotation rates 10 or 20 Hz.

use super::hesai::NEBULA_DRIVER;
use super::{CatalogueEntry, ColumnRule, ReturnMode};
use crate::sensor::Measurement;
use crate::sensor::measure::UNSTATED_DETECTION_REFLECTANCE;

/// Helios elevations by channel, degrees (+14.94 ..= -54.6).
#[rustfmt::skip]
pub const HELIOS_5515_ELEVATION_DEG: [f64; 32] = [
    14.94, 13.03, 10.92, 8.89, 6.96, 5.46, 3.98, 2.67,
    1.33, 0.0, -1.33, -2.67, -3.96, -5.13, -6.53, -7.91,
    -9.89, -15.97, -12.9, -19.08, -22.02, -27.97, -25.16, -31.15,
    -34.09, -37.29, -40.25, -43.71, -46.7, -49.75, -52.7, -54.6,
];
/// Helios azimuth offsets by channel, degrees (positive clockwise).
#[rustfmt::skip]
pub const HELIOS_5515_AZIMUTH_OFFSET_DEG: [f64; 32] = [
    -4.07, 3.63, -4.02, 3.6, -3.99, 3.58, -3.98, 3.57,
    -3.97, 3.57, -3.97, 3.57, -3.98, 3.58, -3.99, 3.59,
    -4.01, 3.66, -4.04, 3.7, -4.19, 3.88, -4.26, 3.97,
    -4.52, 4.14, -4.76, 4.38, -5.03, 4.61, -5.32, 4.8,
];

/// Helios firing time of each channel after its block's start, nanoseconds.
pub const HELIOS_FIRING_OFFSET_NS: [u32; 32] = [
    0, 1570, 3150, 4720, 6300, 7870, 9450, 11360, 13260, 15170, 17080, 18990, 20560, 22140, 23710, 25290, 26530, 29010,
    27770, 30250, 31490, 32730, 33980, 35220, 36460, 37700, 38940, 40180, 41420, 42670, 43910, 45150,
];

/// RoboSense RS-Helios 5515: 55.56 us blocks. 0.2 .. 150 m (nebula's limits), sigma 2 cm, 2.5 mm
/// distance unit (rs_driver).
pub const HELIOS_5515: CatalogueEntry = CatalogueEntry {
    model: "rs-helios-5515",
    product: "RoboSense RS-Helios 5515",
    elevation_deg: &HELIOS_5515_ELEVATION_DEG,
    azimuth_offset_deg: &HELIOS_5515_AZIMUTH_OFFSET_DEG,
    azimuth_sign: -1.0,
    firing_offset_ns: &HELIOS_FIRING_OFFSET_NS,
    beam_origin_m: [0.03498, 0.0, 0.0],
    columns: ColumnRule::FiringCycle { cycle_ns: 55_560 },
    rates_hz: &[10.0, 20.0],
    default_rate_hz: 10.0,
    measurement: Measurement::spinning(0.2, 150.0, 0.02, 0.0025).with_detection(150.0, UNSTATED_DETECTION_REFLECTANCE),
    return_modes: &[ReturnMode::Strongest, ReturnMode::Last, ReturnMode::Dual],
    driver: NEBULA_DRIVER,
};
