//! Bad scene input gives typed errors that name the field, line, range or path.

use std::path::Path;

use scenes::SceneError;
use sim::SemanticClass;

fn load(text: &str) -> Result<scenes::Scene, SceneError> {
    scenes::load_str(text, "bad.toml", Path::new("."), 0)
}

#[test]
fn unknown_param_field_is_rejected_with_its_name_and_line() {
    let e = load("version = 1\nfamily = \"ramp\"\n[params]\nslope_deg = 5.0\nslop_deg = 3.0\n").unwrap_err();
    let msg = e.to_string();
    assert!(matches!(e, SceneError::Toml { .. }), "{e:?}");
    assert!(msg.contains("slop_deg") && msg.contains("line 5"), "{msg}");
    assert!(msg.starts_with("bad.toml: "), "{msg}");
}

#[test]
fn unknown_top_level_field_is_rejected() {
    let msg = load("version = 1\nfamily = \"flat\"\ncolour = \"red\"\n").unwrap_err().to_string();
    assert!(msg.contains("colour") && msg.contains("line 3"), "{msg}");
}

#[test]
fn wrong_or_missing_version_is_rejected() {
    let e = load("version = 2\nfamily = \"flat\"\n").unwrap_err();
    assert!(matches!(e, SceneError::Version { version: 2, .. }), "{e:?}");
    assert!(e.to_string().contains("version = 1"));
    let e = load("family = \"flat\"\n").unwrap_err();
    assert!(e.to_string().contains("missing `version = 1`"), "{e}");
    let e = load("version = \"1\"\nfamily = \"flat\"\n").unwrap_err();
    assert!(e.to_string().contains("must be the integer 1"), "{e}");
}

#[test]
fn out_of_range_slope_names_the_field_and_range() {
    for bad in ["25.0", "-20.5", "nan"] {
        let e = load(&format!("version = 1\nfamily = \"ramp\"\n[params]\nslope_deg = {bad}\n")).unwrap_err();
        match &e {
            SceneError::InvalidParameter { field, allowed, .. } => {
                assert_eq!(field, "params.slope_deg");
                assert_eq!(allowed, "-20 ..= 20");
            }
            other => panic!("{bad}: {other:?}"),
        }
        assert!(e.to_string().contains("params.slope_deg"));
    }
    // A wrong type is a TOML error naming the field.
    let msg = load("version = 1\nfamily = \"ramp\"\n[params]\nslope_deg = \"steep\"\n").unwrap_err().to_string();
    assert!(msg.contains("slope_deg") && msg.contains("line 4"), "{msg}");
}

#[test]
fn other_families_check_their_ranges_too() {
    let cases = [
        ("basin", "depth_m = 0.0", "params.depth_m"),
        ("city", "curb_height_m = 0.5", "params.curb_height_m"),
        ("hill", "slope_deg = 30.0", "params.slope_deg"),
        ("highway", "lanes = 9", "params.lanes"),
        ("forest-dense", "trees_per_ha = -1.0", "params.trees_per_ha"),
        ("garage", "ramp_slope_deg = 2.0", "params.ramp_slope_deg"),
        ("rural", "field_drop_m = 2.0", "params.field_drop_m"),
        ("elevated", "size_m = 1e9", "params.size_m"),
        ("flat", "cell_m = -1.0", "params.cell_m"),
    ];
    for (family, line, field) in cases {
        let e = load(&format!("version = 1\nfamily = \"{family}\"\n[params]\n{line}\n")).unwrap_err();
        assert!(matches!(&e, SceneError::InvalidParameter { field: f, .. } if f == field), "{family}: {e:?}");
    }
}

#[test]
fn unknown_family_and_scene_list_the_known_ones() {
    let e = load("version = 1\nfamily = \"moon\"\n").unwrap_err();
    assert!(e.to_string().contains("moon") && e.to_string().contains("forest-dense"), "{e}");
    let e = scenes::load("nowhere", 0).unwrap_err();
    assert!(matches!(e, SceneError::UnknownScene { .. }));
    assert!(e.to_string().contains("ramp-up") && e.to_string().contains("elevated"), "{e}");
    let e = scenes::load("/does/not/exist.toml", 0).unwrap_err();
    assert!(
        matches!(e, SceneError::Sim(sim::SimError::Io { .. })) && e.to_string().contains("/does/not/exist.toml"),
        "{e}"
    );
}

#[test]
fn missing_mesh_file_gives_its_path() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("s.toml");
    std::fs::write(
        &scene,
        "version = 1\nfamily = \"flat\"\n[[mesh]]\npath = \"gone/statue.obj\"\nclass = \"building\"\n",
    )
    .unwrap();
    let e = scenes::load(scene.to_str().unwrap(), 0).unwrap_err();
    let want = dir.path().join("gone/statue.obj");
    assert!(matches!(&e, SceneError::MeshFile { path, .. } if *path == want), "{e:?}");
    assert!(e.to_string().contains(want.to_str().unwrap()));
}

#[test]
fn user_obj_mesh_is_placed_scaled_and_labelled() {
    let dir = tempfile::tempdir().unwrap();
    // A unit square in the local x-z plane (two triangles, one quad face).
    std::fs::write(dir.path().join("panel.obj"), "v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nf 1 2 3 4\n").unwrap();
    let scene = dir.path().join("s.toml");
    std::fs::write(
        &scene,
        "version = 1\nfamily = \"flat\"\n[params]\nobjects = 0\n[[mesh]]\npath = \"panel.obj\"\nclass = \"other-structure\"\n\
         instance = 77\nposition = [20.0, 5.0, 0.0]\nyaw_deg = 90.0\nscale = 2.0\n",
    )
    .unwrap();
    let s = scenes::load(scene.to_str().unwrap(), 0).unwrap();
    assert_eq!(s.name, "s");
    let tris: Vec<usize> = (0..s.mesh.len()).filter(|&i| s.mesh.surfaces[i].instance == 77).collect();
    assert_eq!(tris.len(), 2);
    assert!(tris.iter().all(|&i| s.mesh.surfaces[i].class == SemanticClass::OTHER_STRUCTURE));
    let pts: Vec<glam::Vec3> = tris.iter().flat_map(|&i| s.mesh.triangle(i)).collect();
    // Yawed 90 deg: local +x becomes world +y; scaled by 2.
    let (lo, hi) = pts.iter().fold((glam::Vec3::MAX, glam::Vec3::MIN), |(l, h), &p| (l.min(p), h.max(p)));
    assert!((lo - glam::Vec3::new(20.0, 5.0, 0.0)).length() < 1e-5, "{lo}");
    assert!((hi - glam::Vec3::new(20.0, 7.0, 2.0)).length() < 1e-5, "{hi}");
}

#[test]
fn user_ply_mesh_is_placed_and_relabelled() {
    let dir = tempfile::tempdir().unwrap();
    let mut box_mesh = sim::SceneMesh::new();
    box_mesh.push_box(glam::Vec3::ZERO, glam::Vec3::ONE, sim::Surface::object(SemanticClass::CAR, 3));
    sim::scene::ply::write_mesh(&dir.path().join("box.ply"), &box_mesh).unwrap();
    let scene = dir.path().join("s.toml");
    std::fs::write(
        &scene,
        "version = 1\nfamily = \"flat\"\n[[mesh]]\npath = \"box.ply\"\nclass = 52\nposition = [30.0, 10.0, 0.0]\n",
    )
    .unwrap();
    let s = scenes::load(scene.to_str().unwrap(), 0).unwrap();
    let tris: Vec<usize> =
        (0..s.mesh.len()).filter(|&i| s.mesh.surfaces[i].class == SemanticClass::OTHER_STRUCTURE).collect();
    assert_eq!(tris.len(), 12);
    let inst = s.mesh.surfaces[tris[0]].instance;
    assert!(inst > 0 && tris.iter().all(|&i| s.mesh.surfaces[i].instance == inst));
    let (lo, hi) = tris
        .iter()
        .flat_map(|&i| s.mesh.triangle(i))
        .fold((glam::Vec3::MAX, glam::Vec3::MIN), |(l, h), p| (l.min(p), h.max(p)));
    assert_eq!((lo, hi), (glam::Vec3::new(30.0, 10.0, 0.0), glam::Vec3::new(31.0, 11.0, 1.0)));
    std::fs::write(dir.path().join("box.ply"), "ply\nformat ascii 1.0\nend_header\n").unwrap();
    let e = scenes::load(scene.to_str().unwrap(), 0).unwrap_err();
    assert!(matches!(&e, SceneError::MeshFile { path, .. } if path.ends_with("box.ply")), "{e:?}");
}

#[test]
fn bad_mesh_entries_are_rejected() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("junk.obj"), "this is not an obj\n").unwrap();
    std::fs::write(dir.path().join("tri.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let cases = [
        ("path = \"junk.obj\"\nclass = \"car\"", "junk.obj"),
        ("path = \"tri.obj\"\nclass = \"spaceship\"", "mesh[0].class"),
        ("path = \"tri.obj\"\nclass = \"car\"\nscale = 0.0", "mesh[0].scale"),
        ("path = \"tri.obj\"\nclass = \"car\"\nreflectivity = 1.5", "mesh[0].reflectivity"),
        ("path = \"tri.obj\"\nclass = \"car\"\nsize = 3", "size"),
        ("path = \"tri.stl\"\nclass = \"car\"", "tri.stl"),
    ];
    for (entry, needle) in cases {
        let scene = dir.path().join("s.toml");
        std::fs::write(&scene, format!("version = 1\nfamily = \"flat\"\n[[mesh]]\n{entry}\n")).unwrap();
        let e = scenes::load(scene.to_str().unwrap(), 0).unwrap_err();
        assert!(e.to_string().contains(needle), "{entry}: {e}");
    }
}

#[test]
fn file_seed_and_caller_seed_add_up() {
    let a = load("version = 1\nfamily = \"flat\"\nseed = 5\n").unwrap();
    let b = scenes::load_str("version = 1\nfamily = \"flat\"\nseed = 2\n", "x", Path::new("."), 3).unwrap().mesh;
    assert_eq!(a.seed, 5);
    assert_eq!(a.mesh, b);
}

#[test]
fn absurd_sizes_are_refused_before_generating() {
    let e = load("version = 1\nfamily = \"flat\"\n[params]\nsize_m = 2000.0\ncell_m = 0.25\n").unwrap_err();
    assert!(matches!(&e, SceneError::InvalidParameter { field, .. } if field == "params.cell_m"), "{e:?}");
    let e =
        load("version = 1\nfamily = \"forest-dense\"\n[params]\nsize_m = 600.0\nshrubs_per_ha = 5000.0\n").unwrap_err();
    assert!(e.to_string().contains("shrubs_per_ha"), "{e}");
}
