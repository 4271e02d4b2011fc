//! Snow lying on the ground: a scene option that covers every ground triangle with a layer of
//! snow, as real snowfall recordings show it (their labels count lying snow as terrain, e.g.
//! WADS's "accumulated snow", which ground classification scores as ground).
//!
//! The layer is the ground raised by its depth, labelled terrain, with snow's reflectivity at the
//! sensors' near-infrared wavelengths. Objects standing on the ground keep their vertices, so the
//! snow reaches up their sides by the depth.

use super::{SceneMesh, SemanticClass};

/// Diffuse reflectivity of fresh, fine-grained snow at 0.9 µm (the 865-905 nm of automotive
/// LiDARs): its spectral albedo there is about 0.85-0.9 for grain radii of 50-200 µm (Warren,
/// "Optical properties of snow", Reviews of Geophysics and Space Physics 20(1), 1982, fig. 7;
/// Wiscombe and Warren, J. Atmos. Sci. 37, 1980). Older, coarser snow reflects less.
pub const SNOW_REFLECTIVITY: f32 = 0.85;

/// Deepest snow cover accepted, metres.
pub const MAX_SNOW_COVER_M: f32 = 1.0;

/// Covers every ground triangle of `mesh` (`SemanticClass::is_ground`) with snow `depth_m` deep:
/// its vertices are raised by `depth_m`, its class becomes terrain and its reflectivity
/// [`SNOW_REFLECTIVITY`]. Returns how many triangles were covered.
///
/// ```
/// use sim::scene::snow_cover::{lay_snow_cover, SNOW_REFLECTIVITY};
/// use sim::{SceneMesh, SemanticClass, Surface};
/// let mut mesh = SceneMesh::new();
/// let a = mesh.push_vertex(glam::Vec3::new(0.0, 0.0, 0.0));
/// let b = mesh.push_vertex(glam::Vec3::new(1.0, 0.0, 0.0));
/// let c = mesh.push_vertex(glam::Vec3::new(0.0, 1.0, 0.0));
/// mesh.push_triangle([a, b, c], Surface::stuff(SemanticClass::ROAD));
/// assert_eq!(lay_snow_cover(&mut mesh, 0.1), 1);
/// assert_eq!(mesh.surfaces[0].class, SemanticClass::TERRAIN);
/// assert_eq!(mesh.surfaces[0].reflectivity, SNOW_REFLECTIVITY);
/// assert!((mesh.vertices[0].z - 0.1).abs() < 1e-6);
/// ```
pub fn lay_snow_cover(mesh: &mut SceneMesh, depth_m: f32) -> usize {
    let mut raise = vec![false; mesh.vertices.len()];
    let mut covered = 0;
    for (triangle, surface) in mesh.triangles.iter().zip(&mut mesh.surfaces) {
        if surface.class.is_ground() {
            for &v in triangle {
                raise[v as usize] = true;
            }
            surface.class = SemanticClass::TERRAIN;
            surface.reflectivity = SNOW_REFLECTIVITY;
            covered += 1;
        }
    }
    for (vertex, up) in mesh.vertices.iter_mut().zip(raise) {
        if up {
            vertex.z += depth_m;
        }
    }
    covered
}
