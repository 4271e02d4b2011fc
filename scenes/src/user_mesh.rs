//! User meshes (`[[mesh]]` entries): OBJ files via `tobj`, PLY files via `sim::scene::ply`, placed
//! with scale, yaw/pitch/roll and position, and labelled with one class and instance.

use std::path::Path;

use glam::{Affine3A, EulerRot, Quat, Vec3};
use sim::{SceneMesh, Surface};

use crate::error::SceneError;
use crate::schema::MeshEntry;

/// Loads the file of `entry` (index `k` in the `[[mesh]]` list), places and labels it.
pub fn load_placed(entry: &MeshEntry, k: usize, base_dir: &Path, instance: u32) -> Result<SceneMesh, SceneError> {
    let field = |f: &str| format!("mesh[{k}].{f}");
    let class = entry.class.resolve(&field("class"))?;
    for (name, v) in [("yaw_deg", entry.yaw_deg), ("pitch_deg", entry.pitch_deg), ("roll_deg", entry.roll_deg)] {
        if !v.is_finite() || v.abs() > 360.0 {
            return Err(SceneError::invalid(field(name), v, "-360 ..= 360"));
        }
    }
    if entry.position.iter().any(|v| !v.is_finite() || v.abs() > 1e5) {
        return Err(SceneError::invalid(field("position"), format!("{:?}", entry.position), "finite, |x| <= 1e5 m"));
    }
    if !(entry.scale.is_finite() && entry.scale > 0.0 && entry.scale <= 1e4) {
        return Err(SceneError::invalid(field("scale"), entry.scale, "0 < scale <= 1e4"));
    }
    let reflectivity = entry.reflectivity.unwrap_or(Surface::object(class, instance).reflectivity);
    if !(0.0..=1.0).contains(&reflectivity) {
        return Err(SceneError::invalid(field("reflectivity"), reflectivity, "0 ..= 1"));
    }
    let path = base_dir.join(&entry.path);
    if !path.is_file() {
        return Err(SceneError::MeshFile { path, message: "file not found".into() });
    }
    let ext = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase()).unwrap_or_default();
    let raw = match ext.as_str() {
        "obj" => read_obj(&path)?,
        "ply" => read_ply(&path)?,
        _ => return Err(SceneError::MeshFile { path, message: "unsupported mesh format (use .obj or .ply)".into() }),
    };
    let rot = Quat::from_euler(
        EulerRot::ZYX,
        entry.yaw_deg.to_radians(),
        entry.pitch_deg.to_radians(),
        entry.roll_deg.to_radians(),
    );
    let world_from_local =
        Affine3A::from_scale_rotation_translation(Vec3::splat(entry.scale), rot, Vec3::from_array(entry.position));
    let surface = Surface { class, instance, reflectivity };
    let mut out = SceneMesh::new();
    out.vertices.extend(raw.vertices.iter().map(|&v| world_from_local.transform_point3(v)));
    out.triangles = raw.triangles;
    out.surfaces = vec![surface; out.triangles.len()];
    out.validate().map_err(|message| SceneError::MeshFile { path, message })?;
    Ok(out)
}

/// Reads the triangles of every model of an OBJ file (faces triangulated; materials ignored).
fn read_obj(path: &Path) -> Result<SceneMesh, SceneError> {
    let err = |message: String| SceneError::MeshFile { path: path.to_path_buf(), message };
    let file = std::fs::File::open(path).map_err(|e| err(e.to_string()))?;
    let opts = tobj::LoadOptions { triangulate: true, single_index: true, ..Default::default() };
    let (models, _materials) =
        tobj::load_obj_buf(&mut std::io::BufReader::new(file), &opts, |_| Err(tobj::LoadError::OpenFileFailed))
            .map_err(|e| err(format!("not a readable OBJ file: {e}")))?;
    let mut mesh = SceneMesh::new();
    for model in models {
        let m = &model.mesh;
        let base = mesh.vertices.len() as u32;
        mesh.vertices.extend(m.positions.chunks_exact(3).map(|p| Vec3::new(p[0], p[1], p[2])));
        let n = (mesh.vertices.len() as u32) - base;
        for t in m.indices.chunks_exact(3) {
            if t.iter().any(|&i| i >= n) {
                return Err(err(format!("face index beyond the {n} vertices of model `{}`", model.name)));
            }
            mesh.triangles.push([base + t[0], base + t[1], base + t[2]]);
        }
    }
    if mesh.triangles.is_empty() {
        return Err(err("no triangles".into()));
    }
    Ok(mesh)
}

/// Reads a PLY mesh (binary or ASCII) with `sim::scene::ply`; its own labels are replaced by the entry's.
fn read_ply(path: &Path) -> Result<SceneMesh, SceneError> {
    sim::scene::ply::read_mesh(path).map_err(|e| SceneError::MeshFile {
        path: path.to_path_buf(),
        message: format!("not a readable PLY mesh: {e}"),
    })
}
