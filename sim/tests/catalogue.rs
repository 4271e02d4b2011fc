//! The sensor catalogue: each table's published figures (channels, elevation extremes, firing
//! cycles and per-channel firing times), points per turn, the roof presets on a flat plane, return
//! modes and the refusal of settings a model lacks.

use sim::Rig;
use sim::SimError;
use sim::scan::{ScanConfig, scan};
use sim::scene::builtin;
use sim::sensor::catalogue::{self, CATALOGUE, CATALOGUE_MODELS, ColumnRule, PointOrder, RingNumbering};
use sim::sensor::{CatalogueEntry, CatalogueSpec, MODELS, ReturnMode, SensorSpec};

fn max(v: &[f64]) -> f64 {
    v.iter().copied().fold(f64::NEG_INFINITY, f64::max)
}

fn min(v: &[f64]) -> f64 {
    v.iter().copied().fold(f64::INFINITY, f64::min)
}

fn cycle_ns(e: &CatalogueEntry) -> Option<u32> {
    match e.columns {
        ColumnRule::FiringCycle { cycle_ns } => Some(cycle_ns),
        ColumnRule::Modes { .. } => None,
    }
}

fn spec_of(model: &str, spec: CatalogueSpec) -> SensorSpec {
    let text = toml::to_string(&spec).unwrap();
    let s: SensorSpec = toml::from_str(&format!("model = \"{model}\"\n{text}")).unwrap();
    assert!(s.catalogued().is_some(), "{model} is not catalogued");
    s
}

fn field_of(spec: &SensorSpec) -> (String, String) {
    match spec.validate("s") {
        Err(SimError::InvalidParameter { field, allowed, .. }) => (field, allowed),
        other => panic!("expected an invalid parameter, got {other:?}"),
    }
}

#[test]
fn the_catalogue_is_listed_among_the_models() {
    assert_eq!(
        CATALOGUE_MODELS,
        ["hdl32e", "vlp32c", "vls128", "os0-128", "os2-128", "pandar64", "pandar-xt32", "rs-helios-5515"]
    );
    for (e, name) in CATALOGUE.iter().zip(CATALOGUE_MODELS) {
        assert!(MODELS.contains(&name), "{name}");
        assert_eq!(catalogue::entry(name), Some(*e));
        let spec = SensorSpec::default_for(name).unwrap();
        assert_eq!(spec.model_name(), name);
        assert_eq!(spec.catalogued().unwrap().0, *e);
        assert_eq!(e.elevation_deg.len(), e.azimuth_offset_deg.len(), "{name}");
        assert_eq!(e.elevation_deg.len(), e.firing_offset_ns.len(), "{name}");
        assert!(e.rates_hz.contains(&e.default_rate_hz), "{name}");
        assert!(e.return_modes.contains(&ReturnMode::Strongest), "{name}: strongest is the default");
        spec.validate("s").unwrap();
    }
    assert!(SensorSpec::default_for("os1-64").unwrap().catalogued().is_none());
}

/// Channels, published elevation extremes (in the table's own order where the vendor numbers
/// from the top), azimuth offset extremes.
#[test]
fn tables_hold_the_published_figures() {
    let cases: [(&CatalogueEntry, usize, f64, f64, f64); 8] = [
        // entry, channels, lowest, highest elevation (deg), largest |azimuth offset| (deg)
        (&catalogue::HDL32E, 32, -30.67, 10.67, 0.0),
        (&catalogue::VLP32C, 32, -25.0, 15.0, 4.2),
        (&catalogue::VLS128, 128, -25.0, 15.0, 6.354),
        (&catalogue::OS0_128, 128, -46.16, 44.30, 11.02),
        (&catalogue::OS2_128, 128, -11.09, 10.76, 2.11),
        (&catalogue::PANDAR64, 64, -24.879, 14.9, 5.208),
        (&catalogue::PANDAR_XT32, 32, -16.023602, 14.972363, 0.129679),
        (&catalogue::HELIOS_5515, 32, -54.6, 14.94, 5.32),
    ];
    for (e, channels, lo, hi, az) in cases {
        assert_eq!(e.channels(), channels, "{}", e.model);
        assert!((min(e.elevation_deg) - lo).abs() < 1e-9, "{}: lowest {}", e.model, min(e.elevation_deg));
        assert!((max(e.elevation_deg) - hi).abs() < 1e-9, "{}: highest {}", e.model, max(e.elevation_deg));
        let az_max = e.azimuth_offset_deg.iter().map(|a| a.abs()).fold(0.0, f64::max);
        assert!((az_max - az).abs() < 1e-9, "{}: |azimuth| up to {az_max}", e.model);
    }
    // Ouster numbers channels from the top: channel 0 is the highest beam, the last the lowest.
    for (e, top, bottom) in [(&catalogue::OS0_128, 44.30, -46.16), (&catalogue::OS2_128, 10.76, -11.09)] {
        assert_eq!((e.elevation_deg[0], e.elevation_deg[127]), (top, bottom), "{}", e.model);
        assert!(e.elevation_deg.windows(2).all(|w| w[1] < w[0]), "{}: not top-down", e.model);
    }
    // HDL-32E: two interleaved ladders 4/3 deg apart (-30.67, -9.33, -29.33, -8.00, ...).
    let hdl = &catalogue::HDL32E;
    assert_eq!(&hdl.elevation_deg[..4], &[-30.67, -9.33, -29.33, -8.0]);
    let mut sorted = hdl.elevation_deg.to_vec();
    sorted.sort_by(f64::total_cmp);
    assert!(sorted.windows(2).all(|w| (w[1] - w[0] - 4.0 / 3.0).abs() < 0.011), "{sorted:?}");
    // VLS-128: 8 azimuth offsets cycling with the laser id.
    let vls = &catalogue::VLS128;
    assert!((0..128).all(|i| vls.azimuth_offset_deg[i] == vls.azimuth_offset_deg[i % 8]));
    // Hesai's first CSV rows as published.
    assert_eq!((catalogue::PANDAR64.elevation_deg[0], catalogue::PANDAR64.azimuth_offset_deg[0]), (14.9, -1.042));
    assert_eq!(
        (catalogue::PANDAR_XT32.elevation_deg[0], catalogue::PANDAR_XT32.azimuth_offset_deg[0]),
        (14.972363, 0.082385)
    );
    // No two channels of a table share an elevation (rows are unambiguous).
    for e in CATALOGUE {
        let mut el = e.elevation_deg.to_vec();
        el.sort_by(f64::total_cmp);
        assert!(el.windows(2).all(|w| w[0] < w[1]), "{}", e.model);
    }
}

#[test]
fn firing_cycles_and_per_channel_times_are_the_published_ones() {
    let ns = |e: &CatalogueEntry, ch: usize| e.firing_offset_ns[ch];
    // HDL-32E: one laser every 1.152 us, 46.08 us cycle.
    let hdl = &catalogue::HDL32E;
    assert_eq!(cycle_ns(hdl), Some(46_080));
    assert!((0..32).all(|ch| ns(hdl, ch) == 1152 * ch as u32));
    // VLP-32C: pairs every 2.304 us, 55.296 us cycle.
    let vlp = &catalogue::VLP32C;
    assert_eq!(cycle_ns(vlp), Some(55_296));
    assert_eq!((ns(vlp, 0), ns(vlp, 1), ns(vlp, 2), ns(vlp, 31)), (0, 0, 2304, 15 * 2304));
    // VLS-128: groups of 8 every 2.665 us, an idle slot after group 8, 53.3 us cycle.
    let vls = &catalogue::VLS128;
    assert_eq!(cycle_ns(vls), Some(53_300));
    assert_eq!(
        (ns(vls, 7), ns(vls, 8), ns(vls, 63), ns(vls, 64), ns(vls, 127)),
        (0, 2665, 7 * 2665, 9 * 2665, 16 * 2665)
    );
    // Pandar64: 55.56 us blocks; the published offsets (before the block's end) + 55.56 us.
    let p64 = &catalogue::PANDAR64;
    assert_eq!(cycle_ns(p64), Some(55_560));
    assert_eq!((ns(p64, 0), ns(p64, 11), ns(p64, 50)), (55_560 - 23_180, 55_560 - 54_668, 55_560 - 3_620));
    // XT32: 368 + 1512 ch ns, 50 us blocks.
    let xt = &catalogue::PANDAR_XT32;
    assert_eq!(cycle_ns(xt), Some(50_000));
    assert!((0..32).all(|ch| ns(xt, ch) == 368 + 1512 * ch as u32));
    // Helios: 55.56 us blocks, 0 .. 45.15 us.
    let helios = &catalogue::HELIOS_5515;
    assert_eq!(cycle_ns(helios), Some(55_560));
    assert_eq!((ns(helios, 0), ns(helios, 1), ns(helios, 31)), (0, 1570, 45_150));
    // Ouster: all channels of a column together; columns from the lidar mode.
    for e in [&catalogue::OS0_128, &catalogue::OS2_128] {
        assert!(e.firing_offset_ns.iter().all(|&t| t == 0));
        assert_eq!(cycle_ns(e), None);
    }
    // Every firing lies inside its cycle.
    for e in CATALOGUE {
        if let Some(c) = cycle_ns(e) {
            assert!(e.firing_offset_ns.iter().all(|&t| t < c), "{}", e.model);
        }
    }
}

/// Columns (firing cycles per turn, rounded) and beams per turn at the rates a model allows.
#[test]
fn points_per_turn_follow_the_firing_cycle() {
    let cases: [(&str, f32, Option<u32>, usize, usize); 12] = [
        // model, rate, Ouster columns, columns, rows
        ("hdl32e", 10.0, None, 2170, 32),
        ("hdl32e", 20.0, None, 1085, 32),
        ("vlp32c", 10.0, None, 1808, 32),
        ("vlp32c", 5.0, None, 3617, 32),
        ("vls128", 10.0, None, 1876, 128),
        ("pandar64", 10.0, None, 1800, 64),
        ("pandar64", 20.0, None, 900, 64),
        ("pandar-xt32", 10.0, None, 2000, 32),
        ("pandar-xt32", 5.0, None, 4000, 32),
        ("rs-helios-5515", 10.0, None, 1800, 32),
        ("os0-128", 10.0, Some(2048), 2048, 128),
        ("os2-128", 20.0, Some(512), 512, 128),
    ];
    for (model, rate, columns, cols, rows) in cases {
        let spec = spec_of(model, CatalogueSpec { frequency_hz: Some(rate), columns, ..Default::default() });
        spec.validate("s").unwrap();
        let p = spec.pattern();
        assert_eq!((p.rows, p.cols), (rows, cols), "{model} at {rate} Hz");
        assert_eq!(p.beam_count(), rows * cols, "{model}");
        assert!((p.frame_period_s - 1.0 / rate as f64).abs() < 1e-12);
    }
}

/// Every cell's time, taken modulo the (stretched) firing cycle, is its channel's firing offset;
/// rows are the channels in elevation order.
#[test]
fn pattern_times_and_rows_follow_the_table() {
    for e in CATALOGUE {
        let spec = SensorSpec::default_for(e.model).unwrap();
        let p = spec.pattern();
        let cycle_s = p.frame_period_s / p.cols as f64;
        let channel_of_row = e.channel_of_row();
        for (row, &ch) in channel_of_row.iter().enumerate() {
            assert!((p.row_elevation_rad[row] as f64 - e.elevation_deg[ch].to_radians()).abs() < 1e-6);
            let tau = e.firing_offset_ns[ch] as f64 * 1e-9;
            for col in (0..p.cols).step_by(97) {
                let t = p.at(row, col).unwrap().time_s;
                let within = t - (t / cycle_s).floor() * cycle_s;
                let d = (within - tau).abs().min((within - tau - cycle_s).abs()).min((within - tau + cycle_s).abs());
                assert!(d < 1e-9, "{} row {row} col {col}: {within} s into its cycle, not {tau}", e.model);
            }
        }
    }
}

#[test]
fn drivers_layouts_are_described() {
    let vlp = &catalogue::VLP32C.driver;
    assert_eq!((vlp.ring, vlp.order), (RingNumbering::ElevationFromBottom, PointOrder::OrganizedBottomFirst));
    assert!(vlp.fields.contains(&("time", "F4")));
    let os = &catalogue::OS0_128.driver;
    assert_eq!((os.ring, os.order), (RingNumbering::TableOrder, PointOrder::OrganizedTopFirst));
    assert!(os.fields.contains(&("t", "U4")) && os.fields.contains(&("range", "U4")));
    for e in [&catalogue::PANDAR64, &catalogue::PANDAR_XT32, &catalogue::HELIOS_5515] {
        assert_eq!((e.driver.ring, e.driver.order), (RingNumbering::TableOrder, PointOrder::FiringOrder));
        assert!(e.driver.fields.contains(&("channel", "U2")) && e.driver.fields.contains(&("return_type", "U1")));
    }
}

#[test]
fn return_modes_set_the_echo_planes_and_a_missing_mode_is_refused() {
    for e in CATALOGUE {
        for mode in ReturnMode::ALL {
            let spec = spec_of(e.model, CatalogueSpec { return_mode: Some(mode), ..Default::default() });
            if e.return_modes.contains(&mode) {
                spec.validate("s").unwrap();
                assert_eq!(spec.measurement().max_echoes, mode.echoes(), "{} {mode:?}", e.model);
            } else {
                let (field, allowed) = field_of(&spec);
                assert_eq!(field, "s.return_mode", "{}", e.model);
                assert!(allowed.contains(&ReturnMode::names(e.return_modes)), "{allowed}");
            }
        }
    }
    // Ouster has no last-return mode.
    let last = spec_of("os2-128", CatalogueSpec { return_mode: Some(ReturnMode::Last), ..Default::default() });
    assert_eq!(
        field_of(&last),
        ("s.return_mode".to_string(), "one of strongest, dual (the Ouster OS2-128's return modes)".to_string())
    );
    // The echo count comes from the return mode only.
    let mut echoes = CatalogueSpec::default();
    echoes.measurement.max_echoes = Some(2);
    assert_eq!(field_of(&spec_of("vlp32c", echoes)).0, "s.measurement.max_echoes");
    // TOML spelling.
    let dual: SensorSpec = toml::from_str("model = \"pandar64\"\nreturn_mode = \"dual\"\n").unwrap();
    assert_eq!(dual.measurement().max_echoes, 2);
    assert!(toml::from_str::<SensorSpec>("model = \"pandar64\"\nreturn_mode = \"first\"\n").is_err());
}

#[test]
fn rates_and_columns_a_model_lacks_are_refused() {
    let odd = spec_of("vlp32c", CatalogueSpec { frequency_hz: Some(10.5), ..Default::default() });
    let (field, allowed) = field_of(&odd);
    assert_eq!(field, "s.frequency_hz");
    assert!(allowed.starts_with("one of 5, 6, 7"), "{allowed}");
    let p64 = spec_of("pandar64", CatalogueSpec { frequency_hz: Some(5.0), ..Default::default() });
    assert_eq!(
        field_of(&p64),
        ("s.frequency_hz".to_string(), "one of 10, 20 (the Hesai Pandar64's rates)".to_string())
    );
    let cols = spec_of("hdl32e", CatalogueSpec { columns: Some(1024), ..Default::default() });
    assert_eq!(field_of(&cols).0, "s.columns");
    let os_cols = spec_of("os0-128", CatalogueSpec { columns: Some(1000), ..Default::default() });
    assert_eq!(field_of(&os_cols), ("s.columns".to_string(), "one of 512, 1024, 2048".to_string()));
    let os_fast =
        spec_of("os0-128", CatalogueSpec { columns: Some(2048), frequency_hz: Some(20.0), ..Default::default() });
    assert_eq!(field_of(&os_fast).0, "s.frequency_hz");
    let err = toml::from_str::<SensorSpec>("model = \"vls128\"\nfrequncy_hz = 10\n").unwrap_err();
    assert!(err.to_string().contains("frequncy_hz"), "{err}");
}

/// Every catalogued roof preset on the flat plane (ideal measurement): every ring whose beams
/// reach the ground inside the plane and the range limits returns in every column; rings that
/// look up return nothing.
#[test]
fn roof_presets_see_the_flat_plane_in_every_ring_that_looks_down() {
    let mesh = builtin::flat();
    let config = ScanConfig { ideal: true, ..ScanConfig::default() };
    for e in CATALOGUE {
        let rig = Rig::preset(&format!("{}-roof", e.model)).unwrap();
        let spec = &rig.sensors[0].spec;
        let (m, p) = (spec.measurement(), spec.pattern());
        let frame = &scan(&mesh, &rig, &config).unwrap()[0];
        let cloud = &frame.cloud;
        assert_eq!((cloud.rows, cloud.cols, cloud.planes), (p.rows, p.cols, 1), "{}", e.model);
        let height_m = rig.sensors[0].mount.z_m as f64;
        let mut looking_down = 0;
        for row in 0..cloud.rows {
            let el = p.row_elevation_rad[row] as f64;
            let returns = (0..cloud.cols).filter(|&c| cloud.has_return(cloud.index(0, row, c))).count();
            if el >= 0.0 {
                assert_eq!(returns, 0, "{}: row {row} looks up ({} deg)", e.model, el.to_degrees());
                continue;
            }
            // Slant and horizontal distance to the ground, with a 10 % margin for beam origins.
            let slant = height_m / (-el).sin();
            let reach = slant * el.cos();
            if slant > 1.1 * m.min_range_m as f64 && slant < 0.9 * m.max_range_m as f64 && reach < 180.0 {
                assert_eq!(returns, cloud.cols, "{}: row {row} ({} deg)", e.model, el.to_degrees());
                looking_down += 1;
            }
        }
        assert!(looking_down >= 8, "{}: only {looking_down} rings reach the ground", e.model);
    }
}

#[test]
fn a_dual_return_scan_has_two_echo_planes() {
    let mesh = builtin::flat_objects();
    let mut rig = Rig::preset("vlp32c-roof").unwrap();
    rig.sensors[0].spec =
        spec_of("vlp32c", CatalogueSpec { return_mode: Some(ReturnMode::Dual), ..Default::default() });
    let frame = &scan(&mesh, &rig, &ScanConfig::default()).unwrap()[0];
    assert_eq!(frame.cloud.planes, 2);
    let second = (0..frame.cloud.rows * frame.cloud.cols)
        .filter(|&i| frame.cloud.has_return(frame.cloud.rows * frame.cloud.cols + i))
        .count();
    assert!(second > 0, "no second echo at the objects' edges");
    assert!(second < frame.cloud.rows * frame.cloud.cols / 10, "{second} second echoes");
}
