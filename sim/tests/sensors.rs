//! Sensor models: grid sizes, exact geometry and timing against the figures of `sensors.md`,
//! destaggering, the nodding mount, TOML parsing and validation.

use std::f64::consts::PI;

use sim::SimError;
use sim::sensor::{
    CustomBeam, CustomSpec, Hdl64eSpec, LuxMode, LuxSpec, NoddingSpec, Os1Gen1Spec, Os1Spec, ScanPattern, SensorSpec,
    TiltMode, Utm30lxSpec, Vlp16Spec,
};
use sim::sensor::{MODELS, velodyne::HDL64E_ELEVATIONS_DEG};

fn elevation_deg(d: glam::Vec3) -> f64 {
    (d.z as f64).asin().to_degrees()
}

fn azimuth_rad(d: glam::Vec3) -> f64 {
    (d.y as f64).atan2(d.x as f64)
}

/// Difference of two angles wrapped to (-pi, pi].
fn angle_diff(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(2.0 * PI);
    if d > PI { d - 2.0 * PI } else { d }
}

/// Checks the properties every pattern shares: sizes, unit directions, times inside the frame,
/// nominal rows increasing and columns decreasing.
fn check_common(p: &ScanPattern) {
    assert_eq!(p.firings.len(), p.rows * p.cols);
    assert_eq!(p.row_elevation_rad.len(), p.rows);
    assert_eq!(p.col_azimuth_rad.len(), p.cols);
    for f in p.firings.iter().flatten() {
        assert!((f.dir_in_sensor.length() - 1.0).abs() < 1e-5, "dir not unit: {:?}", f.dir_in_sensor);
        assert!(f.time_s >= 0.0 && f.time_s < p.frame_period_s, "time {} outside [0, {})", f.time_s, p.frame_period_s);
    }
    assert!(p.row_elevation_rad.windows(2).all(|w| w[1] >= w[0]), "row elevations not sorted");
    assert!(p.col_azimuth_rad.windows(2).all(|w| w[1] < w[0]), "column azimuths not decreasing");
}

/// Checks that rows are sorted by true elevation in every column, and every firing's azimuth lies
/// within `half_width` of its column's nominal azimuth.
fn check_sorted(p: &ScanPattern, half_width_rad: f64) {
    for c in 0..p.cols {
        let mut last = f64::NEG_INFINITY;
        for r in 0..p.rows {
            if let Some(f) = p.at(r, c) {
                let el = elevation_deg(f.dir_in_sensor);
                assert!(el > last, "column {c}: row {r} elevation {el} not above {last}");
                last = el;
                let d = angle_diff(azimuth_rad(f.dir_in_sensor), p.col_azimuth_rad[c] as f64);
                assert!(d.abs() <= half_width_rad, "row {r} col {c}: azimuth off its bin by {} deg", d.to_degrees());
            }
        }
    }
}

fn spinning_half_width(p: &ScanPattern) -> f64 {
    PI / p.cols as f64 + 1e-6
}

#[test]
fn every_model_default_pattern_is_consistent() {
    for model in MODELS {
        let spec = SensorSpec::default_for(model).unwrap();
        assert_eq!(spec.model_name(), *model);
        spec.validate("sensor").unwrap();
        let p = spec.pattern();
        assert!(p.rows > 0 && p.cols > 0, "{model}");
        check_common(&p);
    }
    assert!(matches!(SensorSpec::default_for("vlp32"), Err(SimError::UnknownName { .. })));
}

#[test]
fn nodding_grid_is_200_by_1081_and_721_at_180_deg() {
    let p = NoddingSpec::default().pattern();
    assert_eq!((p.rows, p.cols), (200, 1081));
    assert_eq!(p.beam_count(), 216_200);
    assert!((p.frame_period_s - 5.0).abs() < 1e-12);
    let narrow = NoddingSpec { fov_deg: 180.0, ..Default::default() }.pattern();
    assert_eq!((narrow.rows, narrow.cols), (200, 721));
    // Rows go up in the elevation of the front beam (column 540 of 1081, 360 of 721).
    for (p, front) in [(&p, 540), (&narrow, 360)] {
        check_common(p);
        let f0 = p.at(0, front).unwrap();
        assert!(azimuth_rad(f0.dir_in_sensor).abs() < 1e-6);
        assert!((elevation_deg(f0.dir_in_sensor) + 75.0).abs() < 1e-4);
        let top = p.at(199, front).unwrap();
        assert!((elevation_deg(top.dir_in_sensor) - 55.0).abs() < 1e-4);
        for r in 1..p.rows {
            assert!(
                elevation_deg(p.at(r, front).unwrap().dir_in_sensor)
                    > elevation_deg(p.at(r - 1, front).unwrap().dir_in_sensor)
            );
        }
        // Azimuth decreases along every row.
        for r in [0, 100, 199] {
            for c in 1..p.cols {
                let a = azimuth_rad(p.at(r, c - 1).unwrap().dir_in_sensor);
                let b = azimuth_rad(p.at(r, c).unwrap().dir_in_sensor);
                assert!(b < a, "row {r} col {c}");
            }
        }
    }
}

#[test]
fn nodding_continuous_tilt_is_interpolated_per_beam() {
    let spec = NoddingSpec::default();
    let p = spec.pattern();
    let step_s = 0.025 / 1440.0;
    let rate_deg_per_s = 130.0 / (199.0 * 0.025);
    for r in [0usize, 57, 199] {
        for c in [0usize, 270, 540, 810, 1080] {
            let f = p.at(r, c).unwrap();
            let step = 1080 - c;
            let t = r as f64 * 0.025 + step as f64 * step_s;
            assert!((f.time_s - t).abs() < 1e-12, "time of scan {r} step {step}");
            // The tilt is the rotation about y: recover it from the beam (x = cos t cos p, z = cos t sin p).
            let scan_az = (step as f64 - 540.0) * 0.25;
            let d = f.dir_in_sensor;
            let sign = scan_az.to_radians().cos().signum();
            let pitch = ((sign * d.z as f64).atan2(sign * d.x as f64)).to_degrees();
            let expected = -75.0 + rate_deg_per_s * (t - 540.0 * step_s);
            assert!((pitch - expected).abs() < 1e-3, "scan {r} step {step}: pitch {pitch} vs {expected}");
        }
    }
    // One 270 deg scan spans about 0.49 deg of tilt.
    let span = rate_deg_per_s * 1080.0 * step_s;
    assert!((span - 0.48995).abs() < 1e-4, "{span}");
    // Stepped tilt: all beams of a scan share the scan's nominal pitch.
    let stepped = NoddingSpec { tilt: TiltMode::Stepped, ..Default::default() }.pattern();
    for c in [0usize, 540, 1080] {
        let f = stepped.at(10, c).unwrap();
        let origin = f.origin_in_sensor;
        let pitch = (-(origin.x as f64)).atan2(origin.z as f64).to_degrees();
        assert!((pitch - (-75.0 + 10.0 * 130.0 / 199.0)).abs() < 1e-4, "{pitch}");
    }
}

#[test]
fn nodding_lever_arm_moves_origin_on_a_circle() {
    let spec = NoddingSpec { lever_arm_m: [0.0, 0.0, 0.05], ..Default::default() };
    let p = spec.pattern();
    for r in 0..p.rows {
        let f = p.at(r, 540).unwrap();
        let o = f.origin_in_sensor;
        assert!((o.length() - 0.05).abs() < 1e-6);
        assert!(o.y.abs() < 1e-9);
        // Origin = Ry(-p) (0, 0, 0.05) = 0.05 (-sin p, 0, cos p) with p the front beam's elevation.
        let pitch = elevation_deg(f.dir_in_sensor).to_radians();
        assert!((o.x as f64 + 0.05 * pitch.sin()).abs() < 1e-6);
        assert!((o.z as f64 - 0.05 * pitch.cos()).abs() < 1e-6);
    }
    // At -75 deg (nose down) the scanner's top swings forward.
    assert!(p.at(0, 540).unwrap().origin_in_sensor.x > 0.048);
}

#[test]
fn utm30lx_steps_timing_and_fov_subset() {
    let p = Utm30lxSpec::default().pattern();
    check_common(&p);
    assert_eq!((p.rows, p.cols), (1, 1081));
    // Column 0 is step 1080 (+135 deg), column 1080 is step 0 (-135 deg, fired first).
    assert!((azimuth_rad(p.at(0, 0).unwrap().dir_in_sensor).to_degrees() - 135.0).abs() < 1e-4);
    assert!((azimuth_rad(p.at(0, 540).unwrap().dir_in_sensor)).abs() < 1e-6);
    assert_eq!(p.at(0, 1080).unwrap().time_s, 0.0);
    assert!((p.at(0, 0).unwrap().time_s - 1080.0 * 0.025 / 1440.0).abs() < 1e-12);
    let narrow = Utm30lxSpec { fov_deg: 180.0, ..Default::default() }.pattern();
    assert_eq!(narrow.cols, 721);
    assert!((narrow.col_azimuth_rad[0] as f64 - PI / 2.0).abs() < 1e-6);
    check_sorted(&narrow, 0.125f64.to_radians() + 1e-6);
}

#[test]
fn hdl64e_elevations_equal_the_table_and_offsets_are_representative() {
    let p = Hdl64eSpec::default().pattern();
    check_common(&p);
    assert_eq!((p.rows, p.cols), (64, 2083));
    for (r, &el) in HDL64E_ELEVATIONS_DEG.iter().enumerate() {
        for c in [0usize, 1000, 2082] {
            let f = p.at(r, c).unwrap();
            assert!((elevation_deg(f.dir_in_sensor) - el).abs() < 0.01, "row {r}");
            let o = f.origin_in_sensor;
            assert!((0.14 - 1e-6..=0.22 + 1e-6).contains(&(o.z as f64)), "vertical offset {}", o.z);
            assert!(((o.x.hypot(o.y)) as f64 - 0.026).abs() < 1e-6, "horizontal offset");
        }
    }
    check_sorted(&p, spinning_half_width(&p));
    // Azimuth offsets span -8.5 .. +9.9 deg: the grid is destaggered by up to 57 columns, so the
    // firing placed in a column fired at a different time than its neighbour rows.
    let calib = Hdl64eSpec::calibration();
    let (lo, hi) = calib.iter().fold((f64::MAX, f64::MIN), |(l, h), x| {
        (l.min(x.azimuth_offset_rad.to_degrees()), h.max(x.azimuth_offset_rad.to_degrees()))
    });
    assert!((lo + 8.5).abs() < 1e-9 && (hi - 9.9).abs() < 1e-9);
    let cycle = 0.1 / 2083.0;
    let t0 = p.at(0, 1000).unwrap().time_s;
    let t63 = p.at(63, 1000).unwrap().time_s;
    assert!(((t63 - t0) / cycle).abs() > 10.0);
    // The 2083 columns step 360 / 2083 = 0.17283 deg (the 0.1728 deg of the spec, rounded).
    let step = (p.col_azimuth_rad[0] - p.col_azimuth_rad[1]) as f64;
    assert!((step.to_degrees() - 0.17283).abs() < 1e-4);
}

#[test]
fn lux_constant_resolution_grid() {
    let p = LuxSpec::default().pattern();
    check_common(&p);
    assert_eq!((p.rows, p.cols), (4, 441));
    for (r, el) in [-1.2, -0.4, 0.4, 1.2].iter().enumerate() {
        assert!((p.row_elevation_rad[r] as f64 - f64::to_radians(*el)).abs() < 1e-6);
    }
    check_sorted(&p, 1e-6);
    // Lower two layers cover +50 .. -60 (441 shots), upper two +35 .. -50 (341 shots).
    let per_row: Vec<usize> = (0..4).map(|r| (0..p.cols).filter(|&c| p.at(r, c).is_some()).count()).collect();
    assert_eq!(per_row, vec![441, 441, 341, 341]);
    assert!(p.at(2, 0).is_none() && p.at(0, 0).is_some());
    // Per-shot time = (start - azimuth) / (360 deg * f).
    for c in [0usize, 1, 200, 440] {
        let f = p.at(0, c).unwrap();
        let az = azimuth_rad(f.dir_in_sensor).to_degrees();
        assert!((f.time_s - (50.0 - az) / (360.0 * 12.5)).abs() < 1e-9);
    }
    assert!((p.at(0, 1).unwrap().time_s - 55.556e-6).abs() < 1e-9);
    assert_eq!(LuxSpec { frequency_hz: 25.0, ..Default::default() }.pattern().cols, 441);
    let fast = LuxSpec { frequency_hz: 50.0, ..Default::default() };
    fast.validate("s").unwrap();
    assert_eq!(fast.pattern().cols, 221);
    assert!((fast.pattern().frame_period_s - 0.02).abs() < 1e-12);
    let m = SensorSpec::IbeoLux(LuxSpec::default()).measurement();
    assert_eq!((m.min_range_m, m.max_range_m, m.range_quantum_m, m.max_echoes), (0.3, 200.0, 0.01, 3));
}

#[test]
fn lux_flexible_resolution_sick_map_gives_375_shots() {
    let spec = LuxSpec { mode: LuxMode::Flexible, ..Default::default() };
    spec.validate("s").unwrap();
    let p = spec.pattern();
    check_common(&p);
    assert_eq!((p.rows, p.cols), (4, 375));
    check_sorted(&p, 1e-6);
    // 0.125 deg between +20 and 0, 1 deg between +50 and +35.
    let az: Vec<f64> = p.col_azimuth_rad.iter().map(|a| (*a as f64).to_degrees()).collect();
    assert!((az[0] - 50.0).abs() < 1e-5 && (az[1] - 49.0).abs() < 1e-5);
    let i20 = az.iter().position(|a| (a - 20.0).abs() < 1e-4).unwrap();
    assert!((az[i20] - az[i20 + 1] - 0.125).abs() < 1e-5);
    assert!((az[374] + 59.5).abs() < 1e-5);
    for c in [0usize, i20, 374] {
        let f = p.at(0, c).unwrap();
        assert!((f.time_s - (50.0 - az[c]) / 4500.0).abs() < 1e-9);
    }
    // Flexible only at 12.5 Hz.
    let bad = LuxSpec { mode: LuxMode::Flexible, frequency_hz: 25.0, ..Default::default() };
    assert!(matches!(bad.validate("s"), Err(SimError::InvalidParameter { field, .. }) if field == "s.mode"));
}

#[test]
fn os1_128_modes_and_ring_mapping() {
    for cols in [512u32, 1024, 2048] {
        let spec = Os1Spec { columns: cols, ..Default::default() };
        spec.validate("s").unwrap();
        let p = spec.pattern();
        assert_eq!((p.rows, p.cols), (128, cols as usize));
        check_common(&p);
    }
    let p = Os1Spec::default().pattern();
    assert_eq!((p.rows, p.cols), (128, 2048));
    check_sorted(&p, spinning_half_width(&p));
    assert!((elevation_deg(p.at(0, 0).unwrap().dir_in_sensor) + 22.5).abs() < 1e-4);
    assert!((elevation_deg(p.at(127, 0).unwrap().dir_in_sensor) - 22.5).abs() < 1e-4);
    assert_eq!(sim::sensor::ouster::ouster_channel_of_row(128, 127), 0);
    let o = p.at(5, 77).unwrap().origin_in_sensor;
    assert!((o.z - 0.03618).abs() < 1e-7 && (o.x.hypot(o.y) - 0.015806).abs() < 1e-6);
    // All channels of a column fire together; a column lasts 0.1 s / 2048.
    assert!((p.at(3, 100).unwrap().time_s - 100.0 * 0.1 / 2048.0).abs() < 1e-12);
    assert_eq!(p.at(3, 100).unwrap().time_s, p.at(120, 100).unwrap().time_s);
    let fast = Os1Spec { columns: 2048, frequency_hz: 20.0, ..Default::default() };
    assert!(matches!(fast.validate("s"), Err(SimError::InvalidParameter { field, .. }) if field == "s.frequency_hz"));
    let odd = Os1Spec { columns: 1000, ..Default::default() };
    assert!(matches!(odd.validate("s"), Err(SimError::InvalidParameter { field, .. }) if field == "s.columns"));
}

#[test]
fn os1_64_gen1_is_destaggered() {
    let spec = Os1Gen1Spec::default();
    let p = spec.pattern();
    check_common(&p);
    assert_eq!((p.rows, p.cols), (64, 1024));
    // Uniform 0.527 deg from -16.611 to +16.611.
    for r in 0..64 {
        let el = elevation_deg(p.at(r, 0).unwrap().dir_in_sensor);
        assert!((el - (-16.611 + r as f64 * 33.222 / 63.0)).abs() < 1e-4);
    }
    // The stagger is 9 / 3 columns at 1024 (to 0.0003 deg): every beam sits on its bin centre.
    check_sorted(&p, 1e-3f64.to_radians());
    // The top beam (Ouster channel 0, +3.164 deg left) is seen in column c when the encoder is 9
    // columns further on: it fired at cycle c + 9.
    let cycle = 0.1 / 1024.0;
    for c in [0usize, 500, 1020] {
        assert!((p.at(63, c).unwrap().time_s - ((c + 9) % 1024) as f64 * cycle).abs() < 1e-12);
        assert!((p.at(60, c).unwrap().time_s - ((c + 1024 - 9) % 1024) as f64 * cycle).abs() < 1e-12);
        assert!((p.at(62, c).unwrap().time_s - ((c + 3) % 1024) as f64 * cycle).abs() < 1e-12);
    }
}

#[test]
fn vlp16_interleaved_firing_order_and_timing() {
    let spec = Vlp16Spec::default();
    let p = spec.pattern();
    check_common(&p);
    assert_eq!((p.rows, p.cols), (16, 1808));
    check_sorted(&p, spinning_half_width(&p));
    let cycle = 0.1 / 1808.0;
    for c in [0usize, 1, 900, 1807] {
        let mut by_time: Vec<(f64, f64)> = (0..16)
            .map(|r| {
                let f = p.at(r, c).unwrap();
                (f.time_s, elevation_deg(f.dir_in_sensor))
            })
            .collect();
        by_time.sort_by(|a, b| a.0.total_cmp(&b.0));
        let order: Vec<i32> = by_time.iter().map(|(_, e)| e.round() as i32).collect();
        assert_eq!(order, vec![-15, 1, -13, 3, -11, 5, -9, 7, -7, 9, -5, 11, -3, 13, -1, 15]);
        for (k, (t, _)) in by_time.iter().enumerate() {
            assert!((t - (c as f64 * cycle + k as f64 * 2.304e-6)).abs() < 1e-12, "column {c} slot {k}");
        }
    }
    assert_eq!(Vlp16Spec { frequency_hz: 20.0, ..Default::default() }.columns(), 904);
    assert_eq!(Vlp16Spec { frequency_hz: 5.0, ..Default::default() }.columns(), 3617);
}

#[test]
fn custom_sensor_from_toml_table() {
    let text = r#"
        model = "custom"
        columns = 360
        frequency_hz = 10.0
        [[beams]]
        elevation_deg = 5.0
        azimuth_offset_deg = 2.0
        origin_offset_m = [0.0, 0.0, 0.1]
        [[beams]]
        elevation_deg = -5.0
        time_offset_s = 1e-5
        [measurement]
        range_sigma_m = 0.05
        max_range_m = 50.0
    "#;
    let spec: SensorSpec = toml::from_str(text).unwrap();
    spec.validate("s").unwrap();
    let p = spec.pattern();
    check_common(&p);
    assert_eq!((p.rows, p.cols), (2, 360));
    check_sorted(&p, spinning_half_width(&p));
    assert!((elevation_deg(p.at(0, 10).unwrap().dir_in_sensor) + 5.0).abs() < 1e-4);
    assert!((p.at(1, 10).unwrap().origin_in_sensor.z - 0.1).abs() < 1e-7);
    let m = spec.measurement();
    assert_eq!((m.range_sigma_m, m.max_range_m, m.min_range_m), (0.05, 50.0, 0.5));
    // Azimuth offset of 2 deg = 2 columns at 1 deg per column: the +5 deg beam seen in column c
    // fired two cycles later than the -5 deg beam (which fires 10 us into its cycle).
    let t_hi = p.at(1, 10).unwrap().time_s;
    let t_lo = p.at(0, 10).unwrap().time_s;
    assert!((t_hi - t_lo - (2.0 * 0.1 / 360.0 - 1e-5)).abs() < 1e-9, "{t_hi} {t_lo}");
}

#[test]
fn toml_round_trip_and_unknown_fields() {
    for model in MODELS {
        let spec = SensorSpec::default_for(model).unwrap();
        let text = toml::to_string(&spec).unwrap();
        let back: SensorSpec = toml::from_str(&text).unwrap();
        assert_eq!(back, spec, "{model}:\n{text}");
    }
    let err = toml::from_str::<SensorSpec>("model = \"vlp16\"\nfrequency_hz = 10.0\nfrequncy = 3\n").unwrap_err();
    assert!(err.to_string().contains("frequncy"), "{err}");
    let err = toml::from_str::<SensorSpec>("model = \"ibeo-lux\"\n[measurement]\nsigma = 1\n").unwrap_err();
    assert!(err.to_string().contains("sigma"), "{err}");
    let err = toml::from_str::<SensorSpec>("model = \"velodyne\"\n").unwrap_err();
    assert!(err.to_string().contains("hdl64e"), "{err}");
}

#[test]
fn bad_values_are_refused_with_the_field_named() {
    fn field_of(spec: SensorSpec) -> String {
        match spec.validate("s") {
            Err(SimError::InvalidParameter { field, .. }) => field,
            other => panic!("expected an invalid parameter, got {other:?}"),
        }
    }
    let nan_freq = SensorSpec::Vlp16(Vlp16Spec { frequency_hz: f32::NAN, ..Default::default() });
    assert_eq!(field_of(nan_freq), "s.frequency_hz");
    let zero_cols = SensorSpec::Custom(CustomSpec { columns: 0, ..Default::default() });
    assert_eq!(field_of(zero_cols), "s.columns");
    let no_beams = SensorSpec::Custom(CustomSpec { beams: vec![], ..Default::default() });
    assert_eq!(field_of(no_beams), "s.beams");
    let bad_beam =
        CustomBeam { elevation_deg: f32::NAN, azimuth_offset_deg: 0.0, origin_offset_m: [0.0; 3], time_offset_s: 0.0 };
    let nan_beam = SensorSpec::Custom(CustomSpec { beams: vec![bad_beam], ..Default::default() });
    assert_eq!(field_of(nan_beam), "s.beams[0].elevation_deg");
    let huge = SensorSpec::Custom(CustomSpec { columns: 65_536, beams: vec![bad_beam; 1024], ..Default::default() });
    assert_eq!(field_of(huge), "s.columns");
    let mut negative = Utm30lxSpec::default();
    negative.measurement.max_range_m = Some(-5.0);
    assert_eq!(field_of(SensorSpec::Utm30lx(negative)), "s.measurement.max_range_m");
    let no_scans = SensorSpec::Utm30lxNodding(NoddingSpec { scans: 0, ..Default::default() });
    assert_eq!(field_of(no_scans), "s.scans");
    let odd_fov = SensorSpec::Utm30lx(Utm30lxSpec { fov_deg: 180.1, ..Default::default() });
    assert_eq!(field_of(odd_fov), "s.fov_deg");
    let inverted = SensorSpec::Utm30lxNodding(NoddingSpec { pitch_max_deg: -80.0, ..Default::default() });
    assert_eq!(field_of(inverted), "s.pitch_max_deg");
    let lux_freq = SensorSpec::IbeoLux(LuxSpec { frequency_hz: 10.0, ..Default::default() });
    assert_eq!(field_of(lux_freq), "s.frequency_hz");
    let lux_res = SensorSpec::IbeoLux(LuxSpec { frequency_hz: 50.0, resolution_deg: Some(0.25), ..Default::default() });
    assert_eq!(field_of(lux_res), "s.resolution_deg");
    let hdl_fast = SensorSpec::Hdl64e(Hdl64eSpec { frequency_hz: 20.0, ..Default::default() });
    assert_eq!(field_of(hdl_fast), "s.frequency_hz");
    let mut echoes = LuxSpec::default();
    echoes.measurement.max_echoes = Some(0);
    assert_eq!(field_of(SensorSpec::IbeoLux(echoes)), "s.measurement.max_echoes");
    // Invalid parameters still give a pattern without panicking.
    assert_eq!(SensorSpec::Custom(CustomSpec { columns: 0, ..Default::default() }).pattern().firings.len(), 0);
}

/// Not a timing assertion: prints how long the largest default pattern takes to build.
#[test]
fn os1_128_pattern_build_time_is_reported() {
    let spec = SensorSpec::Os1_128(Os1Spec::default());
    let start = std::time::Instant::now();
    let p = spec.pattern();
    let elapsed = start.elapsed();
    assert_eq!(p.beam_count(), 128 * 2048);
    eprintln!("os1-128 2048 pattern: {:.2} ms", elapsed.as_secs_f64() * 1e3);
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig {
        cases: 48,
        failure_persistence: None,
        ..proptest::prelude::ProptestConfig::default()
    })]
    /// Destaggering is a bijection: in every row of a random custom sensor, the columns hold each
    /// firing cycle of the revolution exactly once, every beam lies within half a column of its
    /// bin, and rows stay sorted by elevation.
    #[test]
    fn destaggering_places_every_firing_once(
        cols in 8u32..400,
        offsets in proptest::collection::vec((-30.0f32..30.0, 0.0f32..3.0), 1..12),
    ) {
        let beams: Vec<CustomBeam> = offsets
            .iter()
            .enumerate()
            .map(|(i, &(az, cycles))| CustomBeam {
                elevation_deg: -20.0 + 2.5 * i as f32,
                azimuth_offset_deg: az,
                origin_offset_m: [0.0; 3],
                time_offset_s: cycles * 0.1 / cols as f32,
            })
            .collect();
        let spec = CustomSpec { columns: cols, beams: beams.clone(), ..Default::default() };
        spec.validate("s").unwrap();
        let p = spec.pattern();
        check_common(&p);
        check_sorted(&p, spinning_half_width(&p));
        let cycle = 0.1 / cols as f64;
        for (r, b) in beams.iter().enumerate() {
            let mut seen = vec![false; cols as usize];
            for c in 0..p.cols {
                let k = (p.at(r, c).unwrap().time_s - b.time_offset_s as f64) / cycle;
                proptest::prop_assert!((k - k.round()).abs() < 1e-6);
                let ki = (k.round() as i64).rem_euclid(cols as i64) as usize;
                proptest::prop_assert!(!seen[ki], "cycle {} twice in row {}", ki, r);
                seen[ki] = true;
            }
        }
    }
}
