//! Rigs: presets and their mounts (the stacked 16- and 28-layer LUX fans of seed 000, the nodding
//! axis of seed 002), TOML files, round trips and bad input.

use std::path::PathBuf;

use sim::SimError;
use sim::rig::{PRESETS, Rig};
use sim::sensor::SensorSpec;

fn rigs_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("rigs")
}

/// Elevations in the vehicle frame (degrees) of every layer of the LUX sensors `range` of `rig`,
/// measured on the beam at sensor azimuth 0, with whether the beam points forward.
fn lux_layer_elevations(rig: &Rig, range: std::ops::Range<usize>) -> Vec<(f64, bool)> {
    let mut out = Vec::new();
    for s in &rig.sensors[range] {
        assert_eq!(s.spec.model_name(), "ibeo-lux");
        let p = s.spec.pattern();
        let col = p.col_azimuth_rad.iter().position(|a| a.abs() < 1e-6).expect("a shot at azimuth 0");
        let vehicle_from_sensor = s.mount.vehicle_from_sensor();
        for r in 0..p.rows {
            let d = vehicle_from_sensor.transform_vector3(p.at(r, col).unwrap().dir_in_sensor);
            out.push(((d.z as f64).asin().to_degrees(), d.x > 0.0));
        }
    }
    out.sort_by(|a, b| a.0.total_cmp(&b.0));
    out
}

fn assert_uniform(elevations: &[f64], spacing_deg: f64) {
    for w in elevations.windows(2) {
        assert!((w[1] - w[0] - spacing_deg).abs() < 1e-3, "layers {} and {} not {spacing_deg} apart", w[0], w[1]);
    }
}

#[test]
fn every_preset_validates() {
    let expected_sensors = [1usize, 4, 7, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1];
    assert_eq!(PRESETS.len(), expected_sensors.len());
    for (name, n) in PRESETS.iter().zip(expected_sensors) {
        let rig = Rig::preset(name).unwrap();
        rig.validate().unwrap();
        assert_eq!(rig.name, *name);
        assert_eq!(rig.sensors.len(), n, "{name}");
        assert_eq!(Rig::load(name).unwrap(), rig);
    }
}

#[test]
fn roof_lux_fans_stack_into_16_layers_0_8_deg_apart() {
    let rig = Rig::preset("lux-roof-4").unwrap();
    let layers = lux_layer_elevations(&rig, 0..4);
    assert_eq!(layers.len(), 16);
    assert!(layers.iter().all(|(_, forward)| *forward));
    let el: Vec<f64> = layers.iter().map(|l| l.0).collect();
    assert_uniform(&el, 0.8);
    assert!((el[0] + 11.6).abs() < 1e-3 && (el[15] - 0.4).abs() < 1e-3, "{el:?}");
    for s in &rig.sensors {
        assert!((s.mount.z_m - 1.6).abs() < 1e-6);
    }
}

#[test]
fn highway_rig_has_28_layers_with_12_looking_back() {
    let rig = Rig::preset("lux-highway-7").unwrap();
    let rows: usize = rig.sensors.iter().map(|s| s.spec.pattern().rows).sum();
    assert_eq!(rows, 28);
    assert_eq!(lux_layer_elevations(&rig, 0..4), lux_layer_elevations(&Rig::preset("lux-roof-4").unwrap(), 0..4));
    let rear = lux_layer_elevations(&rig, 4..7);
    assert_eq!(rear.len(), 12);
    assert!(rear.iter().all(|(_, forward)| !*forward));
    let el: Vec<f64> = rear.iter().map(|l| l.0).collect();
    assert_uniform(&el, 0.8);
    assert!((el[0] + 8.0).abs() < 1e-3 && (el[11] - 0.8).abs() < 1e-3, "{el:?}");
    for s in &rig.sensors[4..] {
        assert_eq!(s.mount.yaw_deg, 180.0);
        assert!(s.mount.x_m < 0.0 && (s.mount.z_m - 0.5).abs() < 1e-6);
    }
}

#[test]
fn nodding_preset_axis_is_0_55_m_above_ground() {
    let rig = Rig::preset("utm30lx-nodding").unwrap();
    let s = &rig.sensors[0];
    assert_eq!(s.mount.z_m, 0.55);
    let p = s.spec.pattern();
    assert_eq!((p.rows, p.cols), (200, 1081));
    // The optical centre is 5 cm from the axis: 0.55 +- 0.05 m above ground.
    let vehicle_from_sensor = s.mount.vehicle_from_sensor();
    for f in p.firings.iter().flatten().step_by(997) {
        let o = vehicle_from_sensor.transform_point3(f.origin_in_sensor);
        assert!(((o - glam::Vec3::new(0.0, 0.0, 0.55)).length() - 0.05).abs() < 1e-5);
    }
}

#[test]
fn spinning_roof_presets_sit_on_the_roof() {
    for (name, model, rows, cols) in [
        ("vlp16-roof", "vlp16", 16, 1808),
        ("hdl64e-roof", "hdl64e", 64, 2083),
        ("os1-64-roof", "os1-64", 64, 1024),
        ("os1-128-roof", "os1-128", 128, 2048),
    ] {
        let rig = Rig::preset(name).unwrap();
        let s = &rig.sensors[0];
        assert_eq!(s.spec.model_name(), model);
        assert!((1.8..=1.9).contains(&s.mount.z_m), "{name}");
        let p = s.spec.pattern();
        assert_eq!((p.rows, p.cols), (rows, cols), "{name}");
    }
}

#[test]
fn presets_round_trip_through_toml() {
    for name in PRESETS {
        let rig = Rig::preset(name).unwrap();
        let text = rig.to_toml_string().unwrap();
        let back = Rig::from_toml_str(&text, format!("{name}.toml")).unwrap();
        assert_eq!(back, rig, "{name}:\n{text}");
    }
}

#[test]
fn example_rig_files_load() {
    let custom = Rig::load(rigs_dir().join("custom-spinning.toml").to_str().unwrap()).unwrap();
    assert_eq!(custom.name, "custom-spinning");
    let p = custom.sensors[0].spec.pattern();
    assert_eq!((p.rows, p.cols), (8, 720));
    assert_eq!(custom.sensors[0].spec.measurement().max_range_m, 80.0);

    let lux = Rig::load(rigs_dir().join("lux-front-flexible.toml").to_str().unwrap()).unwrap();
    let cols: Vec<usize> = lux.sensors.iter().map(|s| s.spec.pattern().cols).collect();
    assert_eq!(cols, vec![375, 441, 441]);
    assert_eq!(lux.sensors[2].spec.measurement().max_echoes, 1);
    assert_eq!(lux.sensors[1].spec.measurement().max_echoes, 3);

    let nod = Rig::load(rigs_dir().join("nodding-180.toml").to_str().unwrap()).unwrap();
    let p = nod.sensors[0].spec.pattern();
    assert_eq!((p.rows, p.cols), (200, 721));
    // The preset of the paper's sparse scene is the same sensor at the same mount.
    let preset = Rig::preset("utm30lx-nodding-180").unwrap();
    assert_eq!(
        (preset.sensors[0].spec.clone(), preset.sensors[0].mount),
        (nod.sensors[0].spec.clone(), nod.sensors[0].mount)
    );
}

#[test]
fn missing_name_becomes_the_file_stem() {
    let text = "[[sensors]]\nname = \"a\"\nmount = { x_m = 0.0, y_m = 0.0, z_m = 1.0 }\nspec = { model = \"vlp16\" }\n";
    let rig = Rig::from_toml_str(text, "/tmp/my-rig.toml").unwrap();
    assert_eq!(rig.name, "my-rig");
    assert!(matches!(rig.sensors[0].spec, SensorSpec::Vlp16(_)));
}

fn toml_message(text: &str) -> String {
    match Rig::from_toml_str(text, "bad.toml") {
        Err(SimError::Toml { message, .. }) => message,
        other => panic!("expected a TOML error, got {other:?}"),
    }
}

fn invalid_field(text: &str) -> String {
    match Rig::from_toml_str(text, "bad.toml") {
        Err(SimError::InvalidParameter { field, .. }) => field,
        other => panic!("expected an invalid parameter, got {other:?}"),
    }
}

const GOOD_HEAD: &str = "name = \"t\"\n[[sensors]]\nname = \"a\"\nmount = { x_m = 0.0, y_m = 0.0, z_m = 1.0 }\n";

#[test]
fn unknown_fields_and_syntax_errors_name_the_field_and_line() {
    let msg = toml_message(&format!("{GOOD_HEAD}spec = {{ model = \"hdl64e\", frequncy_hz = 10.0 }}\n"));
    assert!(msg.contains("frequncy_hz") && msg.contains("line 5"), "{msg}");
    let msg = toml_message(&format!("{GOOD_HEAD}colour = \"red\"\nspec = {{ model = \"vlp16\" }}\n"));
    assert!(msg.contains("colour") && msg.contains("line 5"), "{msg}");
    let msg = toml_message("name = \"t\"\nvehicle = 3\n");
    assert!(msg.contains("vehicle"), "{msg}");
    let msg = toml_message(&format!("{GOOD_HEAD}spec = {{ model = \"vlp32\" }}\n"));
    assert!(msg.contains("vlp32") && msg.contains("os1-128"), "{msg}");
    let msg = toml_message(&format!("{GOOD_HEAD}spec = {{ model = \"vlp16\", frequency_hz = \"fast\" }}\n"));
    assert!(msg.contains("line 5"), "{msg}");
    let msg = toml_message("name = \"t\"\n[[sensors]\n");
    assert!(msg.contains("line 2"), "{msg}");
    let msg = toml_message(
        "name = \"t\"\n[[sensors]]\nname = \"a\"\nmount = { x_m = 0.0, y_m = 0.0, z_m = 1.0, tilt = 3 }\nspec = { model = \"vlp16\" }\n",
    );
    assert!(msg.contains("tilt"), "{msg}");
}

#[test]
fn out_of_range_values_are_refused_with_the_field_named() {
    let nan_mount = "name = \"t\"\n[[sensors]]\nname = \"a\"\nmount = { x_m = 0.0, y_m = 0.0, z_m = nan }\nspec = { model = \"vlp16\" }\n";
    assert_eq!(invalid_field(nan_mount), "sensors[0].mount.z_m");
    let negative_range =
        format!("{GOOD_HEAD}spec = {{ model = \"os1-64\", measurement = {{ max_range_m = -1.0 }} }}\n");
    assert_eq!(invalid_field(&negative_range), "sensors[0].spec.measurement.max_range_m");
    let zero_columns = format!("{GOOD_HEAD}spec = {{ model = \"custom\", columns = 0 }}\n");
    assert_eq!(invalid_field(&zero_columns), "sensors[0].spec.columns");
    let os1_cols = format!("{GOOD_HEAD}spec = {{ model = \"os1-128\", columns = 4096 }}\n");
    assert_eq!(invalid_field(&os1_cols), "sensors[0].spec.columns");
    let nan_pitch = format!("{GOOD_HEAD}spec = {{ model = \"utm30lx-nodding\", pitch_min_deg = nan }}\n");
    assert_eq!(invalid_field(&nan_pitch), "sensors[0].spec.pitch_min_deg");
    let absurd = "name = \"t\"\n[[sensors]]\nname = \"a\"\nmount = { x_m = 1e9, y_m = 0.0, z_m = 1.0 }\nspec = { model = \"vlp16\" }\n";
    assert_eq!(invalid_field(absurd), "sensors[0].mount.x_m");
    let twice = format!(
        "{GOOD_HEAD}spec = {{ model = \"vlp16\" }}\n[[sensors]]\nname = \"a\"\nmount = {{ x_m = 0.0, y_m = 0.0, z_m = 1.0 }}\nspec = {{ model = \"vlp16\" }}\n"
    );
    assert_eq!(invalid_field(&twice), "sensors[1].name");
    assert_eq!(invalid_field("name = \"t\"\nsensors = []\n"), "sensors");
}

#[test]
fn unknown_preset_lists_the_known_ones() {
    let err = Rig::load("lux-roof-5").unwrap_err();
    let text = err.to_string();
    assert!(matches!(err, SimError::UnknownName { kind: "rig", .. }));
    for name in PRESETS {
        assert!(text.contains(name), "{text}");
    }
    assert!(matches!(Rig::load("/nonexistent/rig.toml"), Err(SimError::Io { .. })));
}
