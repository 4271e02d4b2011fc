//! Ouster OS0-128 and OS2-128 (rev6/7).
//!
//! Tables: `beam_altitude_angles` and `beam_azimuth_angles` of the sample metadata in
//! ouster-lidar/ouster-sdk (commit 46b7bcee): `tests/pcaps/OS-0-128_v3.0.1_1024x10.json` and
//! `tests/pcaps/OS-2-128-U1_v2.3.0_1024x10.json`, degrees, in channel order (channel 0 = the top
//! beam). Ouster's `beam_azimuth_angles` are positive clockwise (the SDK's `xyzlut.cpp` turns a
//! beam by `-beam_azimuth`): sign -1. Beam origins: `lidar_origin_to_beam_origin_mm` out from the
//! spin axis along the beam and the `lidar_to_sensor_transform`'s z above the sensor frame's base.
//! All channels of a column fire together. Lidar modes: 512, 1024 or 2048 columns at 10 or 20 Hz,
//! 2048 only at 10 Hz (as the OS1 models).

use super::{CatalogueEntry, ColumnRule, DriverLayout, PointOrder, ReturnMode, RingNumbering};
use crate::sensor::Measurement;
use crate::sensor::measure::UNSTATED_DETECTION_REFLECTANCE;

const MODES: [(u32, &[f32]); 3] = [(512, &[10.0, 20.0]), (1024, &[10.0, 20.0]), (2048, &[10.0])];

/// Ouster's single-return profiles report the strongest return; the dual-return profile the two
/// strongest.
const RETURN_MODES: [ReturnMode; 2] = [ReturnMode::Strongest, ReturnMode::Dual];

/// ouster-ros' `Point` (ROS 2), organized and destaggered.
const DRIVER: DriverLayout = DriverLayout {
    driver: "ouster-lidar/ouster-ros, ouster_ros::Point",
    fields: &[
        ("x", "F4"),
        ("y", "F4"),
        ("z", "F4"),
        ("intensity", "F4"),
        ("t", "U4"),
        ("reflectivity", "U2"),
        ("ring", "U2"),
        ("ambient", "U2"),
        ("range", "U4"),
    ],
    ring: RingNumbering::TableOrder,
    order: PointOrder::OrganizedTopFirst,
    time: "t: nanoseconds after the frame's first column",
};

/// Range noise, quantum, divergence: the OS1 models' representative figures.
const fn measurement(min_range_m: f32, max_range_m: f32) -> Measurement {
    Measurement::spinning(min_range_m, max_range_m, 0.01, 0.001)
}

/// OS0-128 beam altitudes by channel, degrees (+44.30 ..= -46.16).
#[rustfmt::skip]
pub const OS0_128_ELEVATION_DEG: [f64; 128] = [
    44.3, 43.75, 43.02, 42.13, 41.34, 40.76, 40.02, 39.2,
    38.39, 37.81, 37.09, 36.26, 35.48, 34.88, 34.16, 33.36,
    32.57, 31.96, 31.24, 30.46, 29.68, 29.06, 28.35, 27.6,
    26.82, 26.18, 25.48, 24.71, 23.97, 23.34, 22.63, 21.88,
    21.12, 20.48, 19.79, 19.06, 18.31, 17.66, 16.97, 16.22,
    15.5, 14.85, 14.14, 13.42, 12.7, 12.06, 11.35, 10.65,
    9.92, 9.26, 8.58, 7.86, 7.15, 6.48, 5.79, 5.09,
    4.37, 3.71, 3.02, 2.33, 1.61, 0.94, 0.25, -0.45,
    -1.16, -1.83, -2.52, -3.24, -3.92, -4.59, -5.29, -6.0,
    -6.69, -7.38, -8.07, -8.76, -9.46, -10.18, -10.88, -11.54,
    -12.24, -12.96, -13.67, -14.35, -15.04, -15.78, -16.48, -17.12,
    -17.84, -18.6, -19.3, -19.96, -20.66, -21.4, -22.11, -22.78,
    -23.48, -24.27, -24.97, -25.65, -26.34, -27.12, -27.84, -28.5,
    -29.19, -30.0, -30.72, -31.37, -32.07, -32.9, -33.63, -34.28,
    -34.98, -35.82, -36.57, -37.19, -37.91, -38.78, -39.52, -40.16,
    -40.87, -41.76, -42.51, -43.14, -43.88, -44.79, -45.55, -46.16,
];
/// OS0-128 beam azimuths by channel, degrees (positive clockwise).
#[rustfmt::skip]
#[allow(clippy::approx_constant)] // published angles in degrees (3.14, -6.28), not pi
pub const OS0_128_AZIMUTH_OFFSET_DEG: [f64; 128] = [
    10.85, 3.67, -3.4, -10.32, 10.43, 3.53, -3.27, -9.99,
    10.08, 3.4, -3.18, -9.7, 9.77, 3.29, -3.1, -9.44,
    9.5, 3.2, -3.04, -9.21, 9.27, 3.11, -2.98, -9.04,
    9.08, 3.04, -2.93, -8.87, 8.9, 2.97, -2.89, -8.74,
    8.76, 2.92, -2.86, -8.62, 8.63, 2.88, -2.83, -8.53,
    8.52, 2.84, -2.79, -8.45, 8.44, 2.8, -2.77, -8.39,
    8.37, 2.78, -2.78, -8.34, 8.31, 2.75, -2.76, -8.29,
    8.28, 2.75, -2.77, -8.29, 8.26, 2.75, -2.76, -8.31,
    8.25, 2.75, -2.76, -8.3, 8.27, 2.74, -2.79, -8.33,
    8.29, 2.75, -2.8, -8.37, 8.33, 2.78, -2.8, -8.44,
    8.39, 2.79, -2.83, -8.5, 8.47, 2.82, -2.86, -8.61,
    8.56, 2.85, -2.88, -8.71, 8.67, 2.9, -2.92, -8.83,
    8.81, 2.94, -2.98, -8.97, 8.97, 3.0, -3.02, -9.15,
    9.15, 3.07, -3.11, -9.34, 9.37, 3.14, -3.18, -9.6,
    9.62, 3.23, -3.25, -9.87, 9.89, 3.32, -3.35, -10.18,
    10.24, 3.46, -3.46, -10.55, 10.64, 3.6, -3.61, -11.02,
];

/// Ouster OS0-128 (90 deg vertical field of view). Beam origins 27.116 mm out, 38.195 mm up.
/// 0.5 .. 75 m (representative: the metadata carries no range limits).
pub const OS0_128: CatalogueEntry = CatalogueEntry {
    model: "os0-128",
    product: "Ouster OS0-128",
    elevation_deg: &OS0_128_ELEVATION_DEG,
    azimuth_offset_deg: &OS0_128_AZIMUTH_OFFSET_DEG,
    azimuth_sign: -1.0,
    firing_offset_ns: &[0; 128],
    beam_origin_m: [0.027116, 0.0, 0.038195],
    columns: ColumnRule::Modes { modes: &MODES, default_columns: 1024 },
    rates_hz: &[10.0, 20.0],
    default_rate_hz: 10.0,
    measurement: measurement(0.5, 75.0).with_detection(75.0, UNSTATED_DETECTION_REFLECTANCE),
    return_modes: &RETURN_MODES,
    driver: DRIVER,
};

/// OS2-128 beam altitudes by channel, degrees (+10.76 ..= -11.09).
#[rustfmt::skip]
pub const OS2_128_ELEVATION_DEG: [f64; 128] = [
    10.76, 10.58, 10.42, 10.24, 10.1, 9.93, 9.76, 9.57,
    9.41, 9.24, 9.09, 8.91, 8.75, 8.57, 8.41, 8.23,
    8.08, 7.9, 7.74, 7.55, 7.39, 7.21, 7.03, 6.86,
    6.7, 6.53, 6.35, 6.18, 6.02, 5.83, 5.67, 5.5,
    5.32, 5.14, 4.97, 4.81, 4.63, 4.46, 4.28, 4.11,
    3.95, 3.76, 3.58, 3.43, 3.24, 3.07, 2.9, 2.72,
    2.55, 2.37, 2.21, 2.03, 1.87, 1.69, 1.51, 1.32,
    1.16, 0.98, 0.81, 0.63, 0.46, 0.29, 0.11, -0.05,
    -0.25, -0.42, -0.58, -0.76, -0.93, -1.11, -1.28, -1.45,
    -1.63, -1.81, -1.97, -2.16, -2.32, -2.5, -2.68, -2.85,
    -3.02, -3.19, -3.37, -3.55, -3.73, -3.9, -4.07, -4.25,
    -4.4, -4.58, -4.75, -4.94, -5.11, -5.28, -5.46, -5.64,
    -5.8, -5.96, -6.15, -6.32, -6.49, -6.66, -6.84, -7.0,
    -7.17, -7.35, -7.51, -7.69, -7.86, -8.04, -8.22, -8.38,
    -8.55, -8.72, -8.89, -9.06, -9.23, -9.4, -9.57, -9.74,
    -9.91, -10.07, -10.24, -10.41, -10.58, -10.75, -10.92, -11.09,
];
/// OS2-128 beam azimuths by channel, degrees (positive clockwise).
#[rustfmt::skip]
pub const OS2_128_AZIMUTH_OFFSET_DEG: [f64; 128] = [
    2.07, 0.66, -0.71, -2.08, 2.07, 0.69, -0.7, -2.09,
    2.06, 0.67, -0.71, -2.06, 2.06, 0.69, -0.71, -2.07,
    2.07, 0.69, -0.71, -2.07, 2.07, 0.69, -0.7, -2.08,
    2.05, 0.68, -0.69, -2.06, 2.06, 0.69, -0.69, -2.07,
    2.08, 0.69, -0.69, -2.06, 2.08, 0.69, -0.69, -2.07,
    2.08, 0.69, -0.69, -2.05, 2.08, 0.7, -0.68, -2.06,
    2.09, 0.7, -0.67, -2.05, 2.08, 0.7, -0.68, -2.05,
    2.08, 0.71, -0.67, -2.06, 2.08, 0.71, -0.68, -2.05,
    2.07, 0.71, -0.67, -2.05, 2.08, 0.7, -0.68, -2.05,
    2.09, 0.71, -0.66, -2.05, 2.09, 0.71, -0.67, -2.05,
    2.09, 0.71, -0.66, -2.05, 2.1, 0.71, -0.66, -2.05,
    2.09, 0.73, -0.67, -2.05, 2.1, 0.72, -0.66, -2.05,
    2.09, 0.72, -0.66, -2.05, 2.11, 0.73, -0.69, -2.03,
    2.1, 0.72, -0.65, -2.04, 2.11, 0.72, -0.67, -2.05,
    2.1, 0.72, -0.66, -2.04, 2.11, 0.72, -0.66, -2.04,
    2.1, 0.72, -0.65, -2.03, 2.11, 0.73, -0.66, -2.04,
];

/// Ouster OS2-128 (22 deg vertical field of view, long range). Beam origins 13.762 mm out,
/// 78.296 mm up. 0.5 .. 240 m (representative: the metadata carries no range limits).
pub const OS2_128: CatalogueEntry = CatalogueEntry {
    model: "os2-128",
    product: "Ouster OS2-128",
    elevation_deg: &OS2_128_ELEVATION_DEG,
    azimuth_offset_deg: &OS2_128_AZIMUTH_OFFSET_DEG,
    azimuth_sign: -1.0,
    firing_offset_ns: &[0; 128],
    beam_origin_m: [0.013762, 0.0, 0.078296],
    columns: ColumnRule::Modes { modes: &MODES, default_columns: 1024 },
    rates_hz: &[10.0, 20.0],
    default_rate_hz: 10.0,
    measurement: measurement(0.5, 240.0).with_detection(240.0, UNSTATED_DETECTION_REFLECTANCE),
    return_modes: &RETURN_MODES,
    driver: DRIVER,
};
