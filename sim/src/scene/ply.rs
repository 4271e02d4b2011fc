//! Scene meshes as PLY: a binary little-endian writer with per-face class, instance and
//! reflectivity, and a reader of binary or ASCII PLY triangle meshes from other tools.
//!
//! Written layout: `element vertex N` with `float x y z` (world frame, metres), then `element
//! face M` with `list uchar int vertex_indices`, `ushort class` (SemanticKITTI id), `uint instance`
//! and `float reflectivity`. The reader fan-triangulates faces with more than 3 vertices; faces
//! without the per-face fields get class 0, instance 0 and reflectivity 0.3. It never panics on
//! bad input: malformed, truncated or inconsistent files (indices out of range, non-finite
//! coordinates) return [`SimError::BadFile`].

use std::io::Write;
use std::path::Path;

use glam::Vec3;

use super::{SceneMesh, SemanticClass, Surface};
use crate::error::{Result, SimError};
use crate::io::plyfile;

/// Reflectivity given to faces of a file without a `reflectivity` property.
pub const DEFAULT_REFLECTIVITY: f32 = 0.3;

/// Writes `mesh` as a binary little-endian PLY at `path` (atomically).
pub fn write_mesh(path: &Path, mesh: &SceneMesh) -> Result<()> {
    mesh.validate().map_err(|m| SimError::invalid("mesh", m, "a valid mesh"))?;
    let header = format!(
        "ply\nformat binary_little_endian 1.0\ncomment groundtruth scene mesh: metres, class = SemanticKITTI id\n\
         element vertex {}\nproperty float x\nproperty float y\nproperty float z\nelement face {}\n\
         property list uchar int vertex_indices\nproperty ushort class\nproperty uint instance\n\
         property float reflectivity\nend_header\n",
        mesh.vertices.len(),
        mesh.triangles.len()
    );
    crate::io::atomic::write_atomic(path, |w: &mut dyn Write| {
        w.write_all(header.as_bytes())?;
        let mut buf = Vec::with_capacity(1 << 16);
        for v in &mesh.vertices {
            for c in [v.x, v.y, v.z] {
                buf.extend_from_slice(&c.to_le_bytes());
            }
            if buf.len() > 60_000 {
                w.write_all(&buf)?;
                buf.clear();
            }
        }
        for (t, s) in mesh.triangles.iter().zip(&mesh.surfaces) {
            buf.push(3);
            for &i in t {
                // Indices fit in i32: validate() checked them against the vertex count.
                buf.extend_from_slice(&(i as i32).to_le_bytes());
            }
            buf.extend_from_slice(&s.class.0.to_le_bytes());
            buf.extend_from_slice(&s.instance.to_le_bytes());
            buf.extend_from_slice(&s.reflectivity.to_le_bytes());
            if buf.len() > 60_000 {
                w.write_all(&buf)?;
                buf.clear();
            }
        }
        w.write_all(&buf)
    })
}

/// Reads a PLY triangle mesh (binary or ASCII) from `path`.
pub fn read_mesh(path: &Path) -> Result<SceneMesh> {
    let bytes = std::fs::read(path).map_err(|e| SimError::io(path, e))?;
    read_mesh_bytes(path, &bytes)
}

/// Parses PLY mesh `bytes` (read from `path`, named in errors).
pub fn read_mesh_bytes(path: &Path, bytes: &[u8]) -> Result<SceneMesh> {
    let header = plyfile::parse_header(path, bytes)?;
    let find = |name: &str| header.elements.iter().position(|e| e.name == name);
    let ve = find("vertex").ok_or_else(|| SimError::bad_file(path, "PLY mesh has no `vertex` element"))?;
    let fe = find("face").ok_or_else(|| SimError::bad_file(path, "PLY mesh has no `face` element"))?;
    let vel = &header.elements[ve];
    let (Some(ix), Some(iy), Some(iz)) = (vel.scalar_index("x"), vel.scalar_index("y"), vel.scalar_index("z")) else {
        return Err(SimError::bad_file(path, "PLY `vertex` element lacks scalar x, y or z"));
    };
    let fel = &header.elements[fe];
    if !fel.properties.iter().any(|p| {
        matches!(p.kind, plyfile::PlyKind::List { .. }) && (p.name == "vertex_indices" || p.name == "vertex_index")
    }) {
        return Err(SimError::bad_file(path, "PLY `face` element lacks a `vertex_indices` list"));
    }
    let i_class = fel.scalar_index("class");
    let i_inst = fel.scalar_index("instance");
    let i_refl = fel.scalar_index("reflectivity");
    let nv = vel.count;
    let mut mesh = SceneMesh::new();
    mesh.vertices.reserve(nv);
    mesh.triangles.reserve(fel.count);
    mesh.surfaces.reserve(fel.count);
    let mut idx: Vec<u32> = Vec::with_capacity(8);
    plyfile::walk(path, bytes, &header, |e, row, s, list| {
        if e == ve {
            let p = Vec3::new(s[ix] as f32, s[iy] as f32, s[iz] as f32);
            if !p.is_finite() {
                return Err(SimError::bad_file(path, format!("PLY vertex {row} is not finite")));
            }
            mesh.vertices.push(p);
        } else if e == fe {
            if list.len() < 3 {
                return Err(SimError::bad_file(
                    path,
                    format!("PLY face {row} has {} vertices (needs >= 3)", list.len()),
                ));
            }
            idx.clear();
            for &v in list {
                if !(v >= 0.0 && v < nv as f64) || v.fract() != 0.0 {
                    return Err(SimError::bad_file(path, format!("PLY face {row} indexes vertex {v}, file has {nv}")));
                }
                idx.push(v as u32);
            }
            let class = i_class.map_or(0.0, |k| s[k]);
            let instance = i_inst.map_or(0.0, |k| s[k]);
            let refl = i_refl.map_or(f64::from(DEFAULT_REFLECTIVITY), |k| s[k]);
            if !(0.0..=65535.0).contains(&class) || !(0.0..=f64::from(u32::MAX)).contains(&instance) {
                return Err(SimError::bad_file(
                    path,
                    format!("PLY face {row}: class {class} or instance {instance} out of range"),
                ));
            }
            if !(0.0..=1.0).contains(&refl) {
                return Err(SimError::bad_file(path, format!("PLY face {row}: reflectivity {refl} (allowed 0 ..= 1)")));
            }
            let surface =
                Surface { class: SemanticClass(class as u16), instance: instance as u32, reflectivity: refl as f32 };
            for k in 1..idx.len() - 1 {
                mesh.push_triangle([idx[0], idx[k], idx[k + 1]], surface);
            }
        }
        Ok(())
    })?;
    Ok(mesh)
}
