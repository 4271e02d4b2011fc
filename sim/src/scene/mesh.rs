//! The labelled triangle mesh every caster and generator works on.

use glam::{Affine3A, Vec3};
use serde::{Deserialize, Serialize};

use super::SemanticClass;

/// What a triangle is made of: its semantic class, instance and reflectivity.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Surface {
    /// SemanticKITTI class id.
    pub class: SemanticClass,
    /// Instance id: 0 for "stuff" (road, terrain), a fresh id per object otherwise.
    pub instance: u32,
    /// Diffuse (Lambertian) reflectivity in `[0, 1]` at the sensor wavelength.
    pub reflectivity: f32,
}

impl Surface {
    /// A surface of `class` with instance 0 and a typical reflectivity for the class.
    pub fn stuff(class: SemanticClass) -> Self {
        Self { class, instance: 0, reflectivity: default_reflectivity(class) }
    }

    /// A surface of `class` belonging to object `instance`.
    pub fn object(class: SemanticClass, instance: u32) -> Self {
        Self { class, instance, reflectivity: default_reflectivity(class) }
    }
}

/// Typical near-infrared reflectivity of a class (asphalt 0.1, lane paint 0.6, vegetation 0.4, ...).
pub fn default_reflectivity(class: SemanticClass) -> f32 {
    match class.0 {
        40 | 44 => 0.10,
        48 | 49 => 0.20,
        60 => 0.60,
        72 => 0.30,
        70 | 73 => 0.45,
        71 => 0.25,
        10 | 18 | 20 => 0.35,
        30 => 0.30,
        50 | 52 => 0.30,
        51 => 0.40,
        80 => 0.40,
        81 => 0.90,
        _ => 0.30,
    }
}

/// A triangle soup with one [`Surface`] per triangle. Coordinates are metres in the world frame
/// (x forward, y left, z up; the ego vehicle starts at the origin facing +x).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SceneMesh {
    /// Vertex positions, metres.
    pub vertices: Vec<Vec3>,
    /// Triangles as vertex indices, counter-clockwise seen from the front side.
    pub triangles: Vec<[u32; 3]>,
    /// One surface record per triangle.
    pub surfaces: Vec<Surface>,
}

impl SceneMesh {
    /// An empty mesh.
    pub fn new() -> Self {
        Self::default()
    }

    /// Number of triangles.
    pub fn len(&self) -> usize {
        self.triangles.len()
    }

    /// Whether the mesh has no triangles.
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }

    /// Adds a vertex and returns its index.
    pub fn push_vertex(&mut self, p: Vec3) -> u32 {
        self.vertices.push(p);
        (self.vertices.len() - 1) as u32
    }

    /// Adds a triangle over existing vertex indices.
    pub fn push_triangle(&mut self, tri: [u32; 3], surface: Surface) {
        self.triangles.push(tri);
        self.surfaces.push(surface);
    }

    /// Adds a quad `a b c d` (counter-clockwise from the front) as two triangles sharing the edge `a c`.
    pub fn push_quad(&mut self, corners: [Vec3; 4], surface: Surface) {
        let i: Vec<u32> = corners.iter().map(|&p| self.push_vertex(p)).collect();
        self.push_triangle([i[0], i[1], i[2]], surface);
        self.push_triangle([i[0], i[2], i[3]], surface);
    }

    /// Adds an axis-aligned box given its minimum and maximum corners (all six faces, outward).
    pub fn push_box(&mut self, min: Vec3, max: Vec3, surface: Surface) {
        self.push_oriented_box(Affine3A::IDENTITY, min, max, surface);
    }

    /// Adds a box with corners `min..max` in its local frame, placed by `world_from_local`.
    pub fn push_oriented_box(&mut self, world_from_local: Affine3A, min: Vec3, max: Vec3, surface: Surface) {
        let c = |x: f32, y: f32, z: f32| world_from_local.transform_point3(Vec3::new(x, y, z));
        let (a, b) = (min, max);
        let faces = [
            [c(a.x, a.y, a.z), c(a.x, b.y, a.z), c(b.x, b.y, a.z), c(b.x, a.y, a.z)], // bottom (-z)
            [c(a.x, a.y, b.z), c(b.x, a.y, b.z), c(b.x, b.y, b.z), c(a.x, b.y, b.z)], // top (+z)
            [c(a.x, a.y, a.z), c(b.x, a.y, a.z), c(b.x, a.y, b.z), c(a.x, a.y, b.z)], // -y
            [c(a.x, b.y, a.z), c(a.x, b.y, b.z), c(b.x, b.y, b.z), c(b.x, b.y, a.z)], // +y
            [c(a.x, a.y, a.z), c(a.x, a.y, b.z), c(a.x, b.y, b.z), c(a.x, b.y, a.z)], // -x
            [c(b.x, a.y, a.z), c(b.x, b.y, a.z), c(b.x, b.y, b.z), c(b.x, a.y, b.z)], // +x
        ];
        for f in faces {
            self.push_quad(f, surface);
        }
    }

    /// Adds a regular height-field grid over `[x0, x0 + nx*cell] x [y0, y0 + ny*cell]` with
    /// heights from `height(x, y)` and the surface from `surface(x, y)` (evaluated at each cell centre).
    /// Neighbouring cells share vertices, so the grid is a watertight surface.
    pub fn push_heightfield(
        &mut self,
        origin: (f32, f32),
        cell_m: f32,
        (nx, ny): (usize, usize),
        height: impl Fn(f32, f32) -> f32,
        surface: impl Fn(f32, f32) -> Surface,
    ) {
        let base = self.vertices.len() as u32;
        for j in 0..=ny {
            for i in 0..=nx {
                let x = origin.0 + i as f32 * cell_m;
                let y = origin.1 + j as f32 * cell_m;
                self.vertices.push(Vec3::new(x, y, height(x, y)));
            }
        }
        let stride = (nx + 1) as u32;
        for j in 0..ny as u32 {
            for i in 0..nx as u32 {
                let v00 = base + j * stride + i;
                let v10 = v00 + 1;
                let v01 = v00 + stride;
                let v11 = v01 + 1;
                let s = surface(origin.0 + (i as f32 + 0.5) * cell_m, origin.1 + (j as f32 + 0.5) * cell_m);
                self.push_triangle([v00, v10, v11], s);
                self.push_triangle([v00, v11, v01], s);
            }
        }
    }

    /// Appends another mesh.
    pub fn append(&mut self, other: &SceneMesh) {
        let base = self.vertices.len() as u32;
        self.vertices.extend_from_slice(&other.vertices);
        self.triangles.extend(other.triangles.iter().map(|t| [t[0] + base, t[1] + base, t[2] + base]));
        self.surfaces.extend_from_slice(&other.surfaces);
    }

    /// Appends another mesh placed by `world_from_local`.
    pub fn append_transformed(&mut self, other: &SceneMesh, world_from_local: Affine3A) {
        let base = self.vertices.len() as u32;
        self.vertices.extend(other.vertices.iter().map(|&v| world_from_local.transform_point3(v)));
        self.triangles.extend(other.triangles.iter().map(|t| [t[0] + base, t[1] + base, t[2] + base]));
        self.surfaces.extend_from_slice(&other.surfaces);
    }

    /// The three corners of triangle `i`.
    pub fn triangle(&self, i: usize) -> [Vec3; 3] {
        let t = self.triangles[i];
        [self.vertices[t[0] as usize], self.vertices[t[1] as usize], self.vertices[t[2] as usize]]
    }

    /// Unit geometric normal of triangle `i` (right-handed winding), or zero for a degenerate one.
    pub fn triangle_normal(&self, i: usize) -> Vec3 {
        let [a, b, c] = self.triangle(i);
        (b - a).cross(c - a).normalize_or_zero()
    }

    /// Axis-aligned bounds `(min, max)`, or `None` for an empty mesh.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let first = *self.vertices.first()?;
        Some(self.vertices.iter().fold((first, first), |(lo, hi), &v| (lo.min(v), hi.max(v))))
    }

    /// Checks that indices are in range, coordinates finite and surfaces one per triangle.
    pub fn validate(&self) -> Result<(), String> {
        if self.surfaces.len() != self.triangles.len() {
            return Err(format!("{} surfaces for {} triangles", self.surfaces.len(), self.triangles.len()));
        }
        if let Some(v) = self.vertices.iter().position(|v| !v.is_finite()) {
            return Err(format!("vertex {v} is not finite"));
        }
        let n = self.vertices.len() as u32;
        if let Some(t) = self.triangles.iter().position(|t| t.iter().any(|&i| i >= n)) {
            return Err(format!("triangle {t} indexes a vertex beyond {n}"));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn heightfield_counts_and_shared_vertices() {
        let mut m = SceneMesh::new();
        m.push_heightfield((0.0, 0.0), 1.0, (3, 2), |_, _| 0.0, |_, _| Surface::stuff(SemanticClass::ROAD));
        assert_eq!(m.vertices.len(), 4 * 3);
        assert_eq!(m.len(), 2 * 3 * 2);
        for i in 0..m.len() {
            assert!((m.triangle_normal(i) - Vec3::Z).length() < 1e-6, "triangle {i} faces up");
        }
        m.validate().unwrap();
    }

    #[test]
    fn box_has_outward_normals() {
        let mut m = SceneMesh::new();
        m.push_box(Vec3::ZERO, Vec3::ONE, Surface::object(SemanticClass::CAR, 1));
        assert_eq!(m.len(), 12);
        let centre = Vec3::splat(0.5);
        for i in 0..m.len() {
            let [a, b, c] = m.triangle(i);
            let mid = (a + b + c) / 3.0;
            assert!(m.triangle_normal(i).dot(mid - centre) > 0.0, "face {i} points outward");
        }
    }
}
