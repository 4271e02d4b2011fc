//! Tests of the scan spec: round trips, refusals, units and scene resolution.

use super::*;
use crate::mount_override::{MountMode, MountTarget};

fn full() -> ScanSpec {
    ScanSpec {
        scene: "ramp-up".into(),
        params: BTreeMap::from([("slope_deg".to_string(), ParamValue::Float(6.5))]),
        seed: 7,
        rig: "lux-roof-4".into(),
        mount: Some(MountOverride {
            sensor: Some(MountTarget::rig()),
            mode: MountMode::Relative,
            z_m: Some(0.25),
            pitch_deg: Some(-1.5),
            ..Default::default()
        }),
        frames: 3,
        speed_m_per_s: 4.5,
        yaw_rate_deg_per_s: 0.0,
        waypoints_m: Some(vec![[0.0, 0.0], [10.0, 2.5]]),
        ideal: false,
        noise_scale: Some(1.25),
        dropout: Some(0.05),
        intensity_scale: Some(0.8),
        weather: Some(Weather::Fog { visibility_m: 60.0 }),
        backend: Some(ScanBackend::Parry),
        ..ScanSpec::default()
    }
}

#[test]
fn round_trips_through_toml_and_json() {
    let spec = full();
    spec.validate().unwrap();
    let toml_text = spec.to_toml_string().unwrap();
    assert_eq!(ScanSpec::from_toml_str(&toml_text, "t").unwrap(), spec, "{toml_text}");
    let json = serde_json::to_value(&spec).unwrap();
    assert_eq!(ScanSpec::from_json_value(json.clone(), "j").unwrap(), spec, "{json}");
    // A yaw rate given in rad/s survives the trip to the byte.
    let mut s = ScanSpec::default();
    s.set_yaw_rate_rad_per_s(0.3);
    let back = ScanSpec::from_json_value(serde_json::to_value(&s).unwrap(), "j").unwrap();
    assert_eq!(back.yaw_rate_deg_per_s.to_radians() as f32, 0.3f32);
}

#[test]
fn a_yaw_rate_in_rad_per_s_gives_the_same_f32() {
    // Every f32 in the allowed range that a step of 2^-20 of the range (and its neighbours) hits.
    let mut v = -2.0f32;
    let mut checked = 0;
    while v <= 2.0 {
        for w in [v, f32::from_bits(v.to_bits().wrapping_add(1)), f32::from_bits(v.to_bits().wrapping_sub(1))] {
            let mut s = ScanSpec::default();
            s.set_yaw_rate_rad_per_s(w);
            assert_eq!((s.yaw_rate_deg_per_s.to_radians() as f32).to_bits(), w.to_bits(), "{w}");
            checked += 1;
        }
        v += 4.0 / (1 << 20) as f32;
    }
    assert!(checked > 3_000_000);
    for w in [0.3f32, -0.3, 1e-30, 1.9999999, f32::MIN_POSITIVE, 0.0] {
        let mut s = ScanSpec::default();
        s.set_yaw_rate_rad_per_s(w);
        assert_eq!((s.yaw_rate_deg_per_s.to_radians() as f32).to_bits(), w.to_bits(), "{w}");
    }
}

#[test]
fn bad_specs_are_refused_naming_the_field_and_range() {
    let base = "scene = \"flat\"\nrig = \"vlp16-roof\"\nframes = 1\n";
    let cases = [
        ("colour = 1\n", "unknown field `colour`"),
        ("yaw_rate = 0.3\n", "invalid value for `yaw_rate`"),
        ("yaw_rate_rad_per_s = 0.3\n", "invalid value for `yaw_rate_rad_per_s`"),
        ("speed = 3\n", "`speed_m_per_s`, -100 ..= 100"),
        ("mount = { z_m = 150.0 }\n", "invalid value for `mount.z_m`: 150 (allowed: -100 ..= 100)"),
        ("mount = { height = 1.0 }\n", "unknown field `height`"),
        ("yaw_rate_deg_per_s = 200.0\n", "`yaw_rate_deg_per_s`: 200 (allowed: -114.59 ..= 114.59)"),
        ("speed_m_per_s = 101.0\n", "`speed_m_per_s`: 101 (allowed: -100 ..= 100)"),
        ("dropout = 0.95\n", "`dropout`: 0.95 (allowed: 0 ..= 0.9)"),
        ("waypoints_m = [[0, 0]]\n", "waypoints_m"),
        ("backend = \"cuda\"\n", "unknown variant `cuda`"),
        ("snow_cover_m = 0.0\n", "`snow_cover_m`: 0 (allowed: 0 < depth <= 1)"),
        ("snow_cover_m = 1.5\n", "`snow_cover_m`: 1.5 (allowed: 0 < depth <= 1)"),
    ];
    for (extra, needle) in cases {
        let e = ScanSpec::from_toml_str(&format!("{base}{extra}"), "f").unwrap_err().to_string();
        assert!(e.contains(needle), "{extra}: {e}");
        let json: toml::Table = format!("{base}{extra}").parse().unwrap();
        let e = ScanSpec::from_json_value(serde_json::to_value(json).unwrap(), "f").unwrap_err().to_string();
        assert!(e.contains(needle), "{extra} (JSON): {e}");
    }
    assert!(ScanSpec::from_toml_str("rig = \"vlp16-roof\"\n", "f").unwrap_err().to_string().contains("frames"));
    let e = ScanSpec { frames: 0, ..Default::default() }.validate().unwrap_err();
    assert_eq!(e.to_string(), "invalid value for `frames`: 0 (allowed: 1 ..= 100000)");
}

#[test]
fn every_scene_kind_resolves() {
    let kind = |s: &str| SceneSource::resolve(s).unwrap();
    assert_eq!(kind("flat-objects"), SceneSource::Builtin("flat-objects".into()));
    assert_eq!(kind("flat"), SceneSource::Bundled("flat".into()));
    assert_eq!(kind("ramp"), SceneSource::Family("ramp".into()));
    assert_eq!(kind(FIXTURE_TERRAIN), SceneSource::Fixture);
    assert!(matches!(kind("my/scene.toml"), SceneSource::File(_)));
    assert!(matches!(kind("version = 1\nfamily = \"flat\"\n"), SceneSource::Text(_)));
    let e = SceneSource::resolve("moon").unwrap_err().to_string();
    assert!(e.contains("`scene`") && e.contains("flat-objects") && e.contains("fixture-terrain"), "{e}");
    let basin = ScanSpec { scene: String::new(), family: Some("basin".into()), ..Default::default() };
    assert_eq!(basin.scene_source().unwrap(), SceneSource::Family("basin".into()));
    let both = ScanSpec { family: Some("basin".into()), ..Default::default() };
    assert!(both.validate().unwrap_err().to_string().contains("family"));
}

#[test]
fn the_builtin_scene_scans_and_refuses_params() {
    let spec = ScanSpec { ideal: true, ..Default::default() };
    let scene = spec.load_scene().unwrap();
    assert_eq!(scene.family, "flat-objects");
    let setup = spec.setup(&scene).unwrap();
    let frames = sim::scan::scan(&scene.mesh, &setup.rig, &setup.config).unwrap();
    assert!(frames[0].cloud.returns() > 1000);
    let with = ScanSpec { params: BTreeMap::from([("objects".into(), ParamValue::Int(3))]), ..spec };
    assert!(with.load_scene().unwrap_err().to_string().contains("params.objects"));
}

#[test]
fn setup_makes_the_config_the_fields_say() {
    let spec = ScanSpec {
        scene: "flat".into(),
        frames: 2,
        speed_m_per_s: 8.0,
        yaw_rate_deg_per_s: 5.0,
        noise_scale: Some(2.0),
        mount: Some(MountOverride { z_m: Some(2.0), ..Default::default() }),
        ..Default::default()
    };
    let scene = spec.load_scene().unwrap();
    let setup = spec.setup(&scene).unwrap();
    assert_eq!(setup.config.yaw_rate_rad_per_s, 5f64.to_radians() as f32);
    assert_eq!(setup.config.speed_m_per_s, 8.0);
    assert_eq!(setup.config.ego_z_m, scene.ego_ground_z_m);
    assert_eq!(setup.rig.sensors[0].mount.z_m, 2.0);
    let sigma = sim::Rig::preset("vlp16-roof").unwrap().sensors[0].spec.measurement().range_sigma_m;
    assert_eq!(setup.rig.sensors[0].spec.measurement().range_sigma_m, sigma * 2.0);
}

#[test]
fn snow_cover_raises_the_ground_and_makes_it_snow_covered_terrain() {
    let bare = ScanSpec { scene: "rural".into(), rig: "vlp16-roof".into(), frames: 1, ..Default::default() };
    let snowy = ScanSpec { snow_cover_m: Some(0.15), ..bare.clone() };
    let (a, b) = (bare.load_scene().unwrap().mesh, snowy.load_scene().unwrap().mesh);
    assert_eq!(a.triangles, b.triangles);
    let ground: Vec<usize> = (0..a.len()).filter(|&t| a.surfaces[t].class.is_ground()).collect();
    assert!(ground.len() > 1000, "{} ground triangles", ground.len());
    for t in 0..a.len() {
        if a.surfaces[t].class.is_ground() {
            assert_eq!(b.surfaces[t].class, sim::SemanticClass::TERRAIN);
            assert_eq!(b.surfaces[t].reflectivity, sim::scene::snow_cover::SNOW_REFLECTIVITY);
            for &v in &a.triangles[t] {
                let dz = b.vertices[v as usize].z - a.vertices[v as usize].z;
                assert!((dz - 0.15).abs() < 1e-4, "vertex {v} raised {dz}");
            }
        } else {
            assert_eq!(b.surfaces[t], a.surfaces[t]);
        }
    }
}
