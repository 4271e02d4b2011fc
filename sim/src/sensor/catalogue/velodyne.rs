//! Velodyne HDL-32E, VLP-32C and VLS-128.
//!
//! Tables: `vert_correction` (elevation) and `rot_correction` (azimuth offset) of the calibration
//! YAMLs in tier4/nebula, `src/nebula_velodyne/nebula_velodyne_decoders/calibration/` `HDL32.yaml`,
//! `VLP32.yaml`, `VLS128.yaml` (commit 606ac41f), in `laser_id` order, converted from radians to
//! degrees and rounded to 1e-6 deg (the HDL-32E file holds a few values such as -9.3299999 deg: they
//! become -9.33). `rot_correction`
//! is positive to the left: the driver turns a point by `encoder - rot_correction` in its
//! clockwise azimuth (sign +1). Firing times: ros-drivers/velodyne
//! `velodyne_pointcloud/src/lib/rawdata.cc` (commit 30bc444c) and nebula's `vlp32_decoder.cpp`,
//! `vls128_decoder.cpp`. Rotation rates: 300 ..= 1200 rpm in steps of 60 (nebula's
//! `velodyne_hw_interface.cpp`), i.e. 5 ..= 20 Hz in whole hertz.

use super::{CatalogueEntry, ColumnRule, DriverLayout, PointOrder, ReturnMode, RingNumbering};
use crate::sensor::Measurement;
use crate::sensor::measure::UNSTATED_DETECTION_REFLECTANCE;

/// 5 ..= 20 Hz in whole hertz (300 ..= 1200 rpm in steps of 60).
const RATES_HZ: [f32; 16] = [5.0, 6.0, 7.0, 8.0, 9.0, 10.0, 11.0, 12.0, 13.0, 14.0, 15.0, 16.0, 17.0, 18.0, 19.0, 20.0];

const RETURN_MODES: [ReturnMode; 3] = [ReturnMode::Strongest, ReturnMode::Last, ReturnMode::Dual];

/// velodyne_pointcloud's `PointXYZIRT` (ROS 2), organized.
const DRIVER: DriverLayout = DriverLayout {
    driver: "ros-drivers/velodyne velodyne_pointcloud, PointXYZIRT",
    fields: &[("x", "F4"), ("y", "F4"), ("z", "F4"), ("intensity", "F4"), ("ring", "U2"), ("time", "F4")],
    ring: RingNumbering::ElevationFromBottom,
    order: PointOrder::OrganizedBottomFirst,
    time: "time: seconds after the cloud's first firing",
};

/// Measurement figures shared by the three models (range noise, grazing dropout, divergence,
/// echo separation, intensity reference: representative, not from a published file).
const fn measurement(min_range_m: f32, max_range_m: f32, range_sigma_m: f32, range_quantum_m: f32) -> Measurement {
    Measurement::spinning(min_range_m, max_range_m, range_sigma_m, range_quantum_m)
}

/// Firing offsets of `N` lasers fired `per_group` at a time, `spacing_ns` between groups, with
/// `gap_after` groups (0 = none) followed by one idle slot (VLS-128's maintenance slot after group 8).
const fn firing_offsets<const N: usize>(per_group: usize, spacing_ns: u32, gap_after: usize) -> [u32; N] {
    let mut out = [0u32; N];
    let mut n = 0;
    while n < N {
        let group = n / per_group;
        let slot = if gap_after > 0 && group >= gap_after { group + 1 } else { group };
        out[n] = slot as u32 * spacing_ns;
        n += 1;
    }
    out
}

/// HDL-32E elevations by laser id, degrees (-30.67 ..= +10.67, 1.33 deg apart, interleaved).
#[rustfmt::skip]
pub const HDL32E_ELEVATION_DEG: [f64; 32] = [
    -30.67, -9.33, -29.33, -8.0, -28.0, -6.67, -26.67, -5.33,
    -25.33, -4.0, -24.0, -2.67, -22.67, -1.33, -21.33, 0.0,
    -20.0, 1.33, -18.67, 2.67, -17.33, 4.0, -16.0, 5.33,
    -14.67, 6.67, -13.33, 8.0, -12.0, 9.33, -10.67, 10.67,
];
/// HDL-32E azimuth offsets by laser id, degrees (all 0 in the published file).
#[rustfmt::skip]
pub const HDL32E_AZIMUTH_OFFSET_DEG: [f64; 32] = [
    0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
    0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
    0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
    0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0,
];

/// Velodyne HDL-32E: lasers fire one at a time every 1.152 us, a 46.08 us cycle of 40 slots
/// (HDL-32E manual; ros-drivers' `rawdata.cc` uses the same 1.152 / 46.08 us but indexes lasers in
/// pairs, `laser / 2`, a copy of its VLP-32C rule that we do not follow). 0.9 .. 100 m, 2 mm
/// distance unit (the YAML's `distance_resolution`), sigma 2 cm.
pub const HDL32E: CatalogueEntry = CatalogueEntry {
    model: "hdl32e",
    product: "Velodyne HDL-32E",
    elevation_deg: &HDL32E_ELEVATION_DEG,
    azimuth_offset_deg: &HDL32E_AZIMUTH_OFFSET_DEG,
    azimuth_sign: 1.0,
    firing_offset_ns: &firing_offsets::<32>(1, 1152, 0),
    beam_origin_m: [0.0; 3],
    columns: ColumnRule::FiringCycle { cycle_ns: 46_080 },
    rates_hz: &RATES_HZ,
    default_rate_hz: 10.0,
    measurement: measurement(0.9, 100.0, 0.02, 0.002).with_detection(100.0, UNSTATED_DETECTION_REFLECTANCE),
    return_modes: &RETURN_MODES,
    driver: DRIVER,
};

/// VLP-32C elevations by laser id, degrees (-25 ..= +15, non-uniform).
#[rustfmt::skip]
pub const VLP32C_ELEVATION_DEG: [f64; 32] = [
    -25.0, -1.0, -1.667, -15.639, -11.31, 0.0, -0.667, -8.843,
    -7.254, 0.333, -0.333, -6.148, -5.333, 1.333, 0.667, -4.0,
    -4.667, 1.667, 1.0, -3.667, -3.333, 3.333, 2.333, -2.667,
    -3.0, 7.0, 4.667, -2.333, -2.0, 15.0, 10.333, -1.333,
];
/// VLP-32C azimuth offsets by laser id, degrees (+-1.4 and +-4.2).
#[rustfmt::skip]
pub const VLP32C_AZIMUTH_OFFSET_DEG: [f64; 32] = [
    -1.4, 4.2, -1.4, 1.4, -1.4, 1.4, -4.2, 1.4,
    -1.4, 4.2, -1.4, 1.4, -4.2, 1.4, -4.2, 1.4,
    -1.4, 4.2, -1.4, 4.2, -4.2, 1.4, -1.4, 1.4,
    -1.4, 1.4, -1.4, 4.2, -4.2, 1.4, -1.4, 1.4,
];

/// Velodyne VLP-32C: lasers fire in pairs (laser `n` in slot `n / 2`), 2.304 us apart, a 55.296 us
/// cycle (ros-drivers' and nebula's timing tables). 0.9 .. 200 m, 4 mm distance unit (the YAML's
/// `distance_resolution`), sigma 3 cm.
pub const VLP32C: CatalogueEntry = CatalogueEntry {
    model: "vlp32c",
    product: "Velodyne VLP-32C",
    elevation_deg: &VLP32C_ELEVATION_DEG,
    azimuth_offset_deg: &VLP32C_AZIMUTH_OFFSET_DEG,
    azimuth_sign: 1.0,
    firing_offset_ns: &firing_offsets::<32>(2, 2304, 0),
    beam_origin_m: [0.0; 3],
    columns: ColumnRule::FiringCycle { cycle_ns: 55_296 },
    rates_hz: &RATES_HZ,
    default_rate_hz: 10.0,
    measurement: measurement(0.9, 200.0, 0.03, 0.004).with_detection(200.0, UNSTATED_DETECTION_REFLECTANCE),
    return_modes: &RETURN_MODES,
    driver: DRIVER,
};

/// VLS-128 elevations by laser id, degrees (-25 ..= +15, non-uniform).
#[rustfmt::skip]
#[allow(clippy::approx_constant)] // published angles in degrees (3.14, -6.28), not pi
pub const VLS128_ELEVATION_DEG: [f64; 128] = [
    -11.742, -1.99, 3.4, -5.29, -0.78, 4.61, -4.08, 1.31,
    -6.5, -1.11, 4.28, -4.41, 0.1, 6.48, -3.2, 2.19,
    -3.86, 1.53, -9.244, -1.77, 2.74, -5.95, -0.56, 4.83,
    -2.98, 2.41, -6.28, -0.89, 3.62, -5.07, 0.32, 7.58,
    -0.34, 5.18, -3.64, 1.75, -25.0, -2.43, 2.96, -5.73,
    0.54, 9.7, -2.76, 2.63, -7.65, -1.55, 3.84, -4.85,
    3.18, -5.51, -0.12, 5.73, -4.3, 1.09, -16.042, -2.21,
    4.06, -4.63, 0.76, 15.0, -3.42, 1.97, -6.85, -1.33,
    -5.62, -0.23, 5.43, -3.53, 0.98, -19.582, -2.32, 3.07,
    -4.74, 0.65, 11.75, -2.65, 1.86, -7.15, -1.44, 3.95,
    -2.1, 3.29, -5.4, -0.01, 4.5, -4.19, 1.2, -13.565,
    -1.22, 4.17, -4.52, 0.87, 6.08, -3.31, 2.08, -6.65,
    1.42, -10.346, -1.88, 3.51, -6.06, -0.67, 4.72, -3.97,
    2.3, -6.39, -1.0, 4.39, -5.18, 0.21, 6.98, -3.09,
    4.98, -3.75, 1.64, -8.352, -2.54, 2.85, -5.84, -0.45,
    8.43, -2.87, 2.52, -6.17, -1.66, 3.73, -4.96, 0.43,
];
/// VLS-128 azimuth offsets by laser id, degrees (8 values cycling with the laser id, +-6.354).
#[rustfmt::skip]
pub const VLS128_AZIMUTH_OFFSET_DEG: [f64; 128] = [
    -6.354, -4.548, -2.732, -0.911, 0.911, 2.732, 4.548, 6.354,
    -6.354, -4.548, -2.732, -0.911, 0.911, 2.732, 4.548, 6.354,
    -6.354, -4.548, -2.732, -0.911, 0.911, 2.732, 4.548, 6.354,
    -6.354, -4.548, -2.732, -0.911, 0.911, 2.732, 4.548, 6.354,
    -6.354, -4.548, -2.732, -0.911, 0.911, 2.732, 4.548, 6.354,
    -6.354, -4.548, -2.732, -0.911, 0.911, 2.732, 4.548, 6.354,
    -6.354, -4.548, -2.732, -0.911, 0.911, 2.732, 4.548, 6.354,
    -6.354, -4.548, -2.732, -0.911, 0.911, 2.732, 4.548, 6.354,
    -6.354, -4.548, -2.732, -0.911, 0.911, 2.732, 4.548, 6.354,
    -6.354, -4.548, -2.732, -0.911, 0.911, 2.732, 4.548, 6.354,
    -6.354, -4.548, -2.732, -0.911, 0.911, 2.732, 4.548, 6.354,
    -6.354, -4.548, -2.732, -0.911, 0.911, 2.732, 4.548, 6.354,
    -6.354, -4.548, -2.732, -0.911, 0.911, 2.732, 4.548, 6.354,
    -6.354, -4.548, -2.732, -0.911, 0.911, 2.732, 4.548, 6.354,
    -6.354, -4.548, -2.732, -0.911, 0.911, 2.732, 4.548, 6.354,
    -6.354, -4.548, -2.732, -0.911, 0.911, 2.732, 4.548, 6.354,
];

/// Velodyne VLS-128: 8 lasers fire together (laser `n` in group `n / 8`), 2.665 us per group, with
/// one idle slot after group 8 (the `+ laser / 64` of the timing tables), a 53.3 us cycle. 0.9 ..
/// 245 m, 4 mm distance unit (ros-drivers' `VLS128_DISTANCE_RESOLUTION`), sigma 3 cm.
pub const VLS128: CatalogueEntry = CatalogueEntry {
    model: "vls128",
    product: "Velodyne VLS-128",
    elevation_deg: &VLS128_ELEVATION_DEG,
    azimuth_offset_deg: &VLS128_AZIMUTH_OFFSET_DEG,
    azimuth_sign: 1.0,
    firing_offset_ns: &firing_offsets::<128>(8, 2665, 8),
    beam_origin_m: [0.0; 3],
    columns: ColumnRule::FiringCycle { cycle_ns: 53_300 },
    rates_hz: &RATES_HZ,
    default_rate_hz: 10.0,
    measurement: measurement(0.9, 245.0, 0.03, 0.004).with_detection(245.0, UNSTATED_DETECTION_REFLECTANCE),
    return_modes: &RETURN_MODES,
    driver: DRIVER,
};
