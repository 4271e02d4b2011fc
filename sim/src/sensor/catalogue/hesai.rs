//! Hesai Pandar64 and PandarXT-32.
//!
//! Tables: the angle-correction CSVs in tier4/nebula (commit 606ac41f),
//! `src/nebula_hesai/nebula_hesai_decoders/calibration/Pandar64.csv` and `PandarXT32.csv`
//! (`Laser id,Elevation,Azimuth` / `Channel,Elevation,Azimuth`, degrees), in laser id order (id 1
//! first). Hesai's azimuth is clockwise (nebula's decoder puts a point at `x = d sin(a)`,
//! `y = d cos(a)` with `a = block azimuth + offset`): sign -1. Firing times, block times and range
//! limits: nebula's `decoders/pandar_64.hpp` and `pandar_xt32.hpp`. Rotation rates: Hesai's
//! 300 / 600 / 1200 rpm (nebula's `hesai_hw_interface.hpp`); the Pandar64 runs at 10 or 20 Hz.

use super::{CatalogueEntry, ColumnRule, DriverLayout, PointOrder, ReturnMode, RingNumbering};
use crate::sensor::Measurement;

const RETURN_MODES: [ReturnMode; 3] = [ReturnMode::Strongest, ReturnMode::Last, ReturnMode::Dual];

/// nebula's `PointXYZIRCAEDT` (ROS 2), one row in firing order.
pub(super) const NEBULA_DRIVER: DriverLayout = DriverLayout {
    driver: "tier4/nebula, PointXYZIRCAEDT",
    fields: &[
        ("x", "F4"),
        ("y", "F4"),
        ("z", "F4"),
        ("intensity", "U1"),
        ("return_type", "U1"),
        ("channel", "U2"),
        ("azimuth", "F4"),
        ("elevation", "F4"),
        ("distance", "F4"),
        ("time_stamp", "U4"),
    ],
    ring: RingNumbering::TableOrder,
    order: PointOrder::FiringOrder,
    time: "time_stamp: nanoseconds after the cloud's header stamp",
};

/// Range noise, grazing dropout, divergence, echo separation and intensity reference are
/// representative, not from a published file.
const fn measurement(min_range_m: f32, max_range_m: f32, range_sigma_m: f32) -> Measurement {
    Measurement::spinning(min_range_m, max_range_m, range_sigma_m, 0.004)
}

/// Pandar64 elevations by laser id, degrees (+14.9 ..= -24.879).
#[rustfmt::skip]
pub const PANDAR64_ELEVATION_DEG: [f64; 64] = [
    14.9, 11.05, 8.077, 5.075, 3.058, 2.046, 1.878, 1.706,
    1.54, 1.369, 1.202, 1.031, 0.864, 0.693, 0.526, 0.355,
    0.187, 0.018, -0.151, -0.319, -0.49, -0.657, -0.827, -0.995,
    -1.166, -1.333, -1.504, -1.67, -1.842, -2.01, -2.18, -2.347,
    -2.518, -2.682, -2.855, -3.022, -3.192, -3.357, -3.53, -3.694,
    -3.866, -4.032, -4.203, -4.367, -4.54, -4.702, -4.874, -5.039,
    -5.211, -5.373, -5.547, -5.708, -5.88, -6.043, -7.045, -8.041,
    -9.042, -10.027, -11.014, -11.988, -12.956, -13.912, -18.871, -24.879,
];
/// Pandar64 azimuth offsets by laser id, degrees (positive clockwise).
#[rustfmt::skip]
pub const PANDAR64_AZIMUTH_OFFSET_DEG: [f64; 64] = [
    -1.042, -1.042, -1.042, -1.042, -1.042, -1.042, 1.042, 3.125,
    5.208, -5.208, -3.125, -1.042, 1.042, 3.125, 5.208, -5.208,
    -3.125, -1.042, 1.042, 3.125, 5.208, -5.208, -3.125, -1.042,
    1.042, 3.125, 5.208, -5.208, -3.125, -1.042, 1.042, 3.125,
    5.208, -5.208, -3.125, -1.042, 1.042, 3.125, 5.208, -5.208,
    -3.125, -1.042, 1.042, 3.125, 5.208, -5.208, -3.125, -1.042,
    1.042, 3.125, 5.208, -5.208, -3.125, -1.042, -1.042, -1.042,
    -1.042, -1.042, -1.042, -1.042, -1.042, -1.042, -1.042, -1.042,
];

/// Pandar64 firing time offsets by channel as published (nebula's `firing_time_offset_ns`),
/// nanoseconds relative to the end of the 55.56 us block.
pub const PANDAR64_FIRING_OFFSET_PUBLISHED_NS: [i32; 64] = [
    -23180, -21876, -20572, -19268, -17964, -16660, -11444, -46796, -7532, -36956, -50732, -54668, -40892, -44828,
    -31052, -34988, -48764, -52700, -38924, -42860, -29084, -33020, -46796, -25148, -36956, -50732, -27116, -40892,
    -44828, -31052, -34988, -48764, -25148, -38924, -42860, -29084, -33020, -52700, -6228, -54668, -15356, -27116,
    -10140, -23180, -4924, -21876, -14052, -17964, -8836, -19268, -3620, -20572, -12748, -16660, -7532, -11444, -6228,
    -15356, -10140, -4924, -3620, -14052, -8836, -12748,
];

/// Pandar64 block (firing cycle), nanoseconds.
pub const PANDAR64_CYCLE_NS: u32 = 55_560;

/// `published` moved from "before the block's end" to "after the block's start": `+ cycle_ns`.
const fn after_cycle_start<const N: usize>(published: [i32; N], cycle_ns: i32) -> [u32; N] {
    let mut out = [0u32; N];
    let mut i = 0;
    while i < N {
        out[i] = (published[i] + cycle_ns) as u32;
        i += 1;
    }
    out
}

/// Hesai Pandar64: 55.56 us blocks, channels fired at the published offsets (0.89 .. 51.94 us after
/// the block's start). 0.3 .. 200 m, sigma 2 cm, 4 mm distance unit.
pub const PANDAR64: CatalogueEntry = CatalogueEntry {
    model: "pandar64",
    product: "Hesai Pandar64",
    elevation_deg: &PANDAR64_ELEVATION_DEG,
    azimuth_offset_deg: &PANDAR64_AZIMUTH_OFFSET_DEG,
    azimuth_sign: -1.0,
    firing_offset_ns: &after_cycle_start(PANDAR64_FIRING_OFFSET_PUBLISHED_NS, PANDAR64_CYCLE_NS as i32),
    beam_origin_m: [0.0; 3],
    columns: ColumnRule::FiringCycle { cycle_ns: PANDAR64_CYCLE_NS },
    rates_hz: &[10.0, 20.0],
    default_rate_hz: 10.0,
    measurement: measurement(0.3, 200.0, 0.02).with_detection(200.0, 0.1),
    return_modes: &RETURN_MODES,
    driver: NEBULA_DRIVER,
};

/// PandarXT-32 elevations by channel, degrees (+14.97 ..= -16.02, about 1 deg apart).
#[rustfmt::skip]
pub const PANDAR_XT32_ELEVATION_DEG: [f64; 32] = [
    14.972363, 13.952372, 12.938632, 11.931141, 10.926151, 9.92241, 8.917419, 7.917429,
    6.919938, 5.919947, 4.922456, 3.924965, 2.929974, 1.936233, 0.944992, -0.0475,
    -1.039991, -2.036232, -3.028723, -4.024964, -5.019955, -6.016196, -7.013687, -8.013678,
    -9.011169, -10.011159, -11.00615, -12.003641, -12.996131, -13.997372, -15.004862, -16.023602,
];
/// PandarXT-32 azimuth offsets by channel, degrees (positive clockwise).
#[rustfmt::skip]
pub const PANDAR_XT32_AZIMUTH_OFFSET_DEG: [f64; 32] = [
    0.082385, 0.076529, 0.07824, 0.076267, 0.064337, 0.059942, 0.049319, 0.044992,
    0.034446, 0.027658, 0.020896, 0.014147, 0.008668, -0.000548, -0.007248, -0.015201,
    -0.025654, -0.031126, -0.037837, -0.045822, -0.061312, -0.06557, -0.068599, -0.076658,
    -0.088476, -0.09158, -0.098438, -0.092837, -0.102247, -0.104231, -0.118783, -0.129679,
];

/// `368 + 1512 ch` nanoseconds for channel `ch` (nebula's `pandar_xt32.hpp`).
const fn xt32_firing_offsets() -> [u32; 32] {
    let mut out = [0u32; 32];
    let mut ch = 0;
    while ch < 32 {
        out[ch] = 368 + 1512 * ch as u32;
        ch += 1;
    }
    out
}

/// Hesai PandarXT-32: 50 us blocks, channel `ch` fired `368 + 1512 ch` ns after the block's start.
/// 0.05 .. 120 m, sigma 1 cm, 4 mm distance unit.
pub const PANDAR_XT32: CatalogueEntry = CatalogueEntry {
    model: "pandar-xt32",
    product: "Hesai PandarXT-32",
    elevation_deg: &PANDAR_XT32_ELEVATION_DEG,
    azimuth_offset_deg: &PANDAR_XT32_AZIMUTH_OFFSET_DEG,
    azimuth_sign: -1.0,
    firing_offset_ns: &xt32_firing_offsets(),
    beam_origin_m: [0.0; 3],
    columns: ColumnRule::FiringCycle { cycle_ns: 50_000 },
    rates_hz: &[5.0, 10.0, 20.0],
    default_rate_hz: 10.0,
    measurement: measurement(0.05, 120.0, 0.01).with_detection(80.0, 0.1),
    return_modes: &RETURN_MODES,
    driver: NEBULA_DRIVER,
};
