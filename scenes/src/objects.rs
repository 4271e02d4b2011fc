//! The object library: honest, low-polygon shapes with their semantic classes. Every object takes a
//! fresh instance id from [`Ids`]; all parts of one object (a tree's trunk and crown, a sign's post
//! and plate) share it. Objects are placed by their ground point (`base`, the centre of their
//! footprint on the ground) and a heading `yaw_rad` about +z (0 = facing +x).

use glam::{Affine3A, Quat, Vec3};
use sim::{SceneMesh, SemanticClass, Surface};

/// Hands out fresh instance ids (1, 2, 3, ...; 0 is "stuff").
#[derive(Clone, Debug)]
pub struct Ids {
    next: u32,
}

impl Default for Ids {
    fn default() -> Self {
        Self { next: 1 }
    }
}

impl Ids {
    /// The next unused instance id.
    pub fn fresh(&mut self) -> u32 {
        let id = self.next;
        self.next += 1;
        id
    }
}

/// The placement of an object standing at `base` with heading `yaw_rad`.
pub fn pose(base: Vec3, yaw_rad: f32) -> Affine3A {
    Affine3A::from_rotation_translation(Quat::from_rotation_z(yaw_rad), base)
}

/// A vertical prism with `sides` sides (a cylinder), radius `radius_m`, from `z0` to `z1` in the
/// local frame of `world_from_local`, capped at both ends.
pub fn push_prism(
    mesh: &mut SceneMesh,
    world_from_local: Affine3A,
    sides: u32,
    radius_m: f32,
    (z0, z1): (f32, f32),
    s: Surface,
) {
    let n = sides.max(3);
    let base = mesh.vertices.len() as u32;
    for k in 0..n {
        let a = k as f32 / n as f32 * std::f32::consts::TAU;
        let (sa, ca) = a.sin_cos();
        mesh.vertices.push(world_from_local.transform_point3(Vec3::new(radius_m * ca, radius_m * sa, z0)));
        mesh.vertices.push(world_from_local.transform_point3(Vec3::new(radius_m * ca, radius_m * sa, z1)));
    }
    for k in 0..n {
        let (b0, t0) = (base + 2 * k, base + 2 * k + 1);
        let (b1, t1) = (base + 2 * ((k + 1) % n), base + 2 * ((k + 1) % n) + 1);
        mesh.push_triangle([b0, b1, t1], s);
        mesh.push_triangle([b0, t1, t0], s);
    }
    for k in 1..n - 1 {
        mesh.push_triangle([base + 1, base + 2 * k + 1, base + 2 * (k + 1) + 1], s);
        mesh.push_triangle([base, base + 2 * (k + 1), base + 2 * k], s);
    }
}

/// An ellipsoid with semi-axes `radii_m` centred at `centre` (local frame), `rings` x `segments`.
pub fn push_ellipsoid(
    mesh: &mut SceneMesh,
    world_from_local: Affine3A,
    centre: Vec3,
    radii_m: Vec3,
    (rings, segments): (u32, u32),
    s: Surface,
) {
    let (rings, segments) = (rings.max(2), segments.max(3));
    let base = mesh.vertices.len() as u32;
    let top = mesh.push_vertex(world_from_local.transform_point3(centre + Vec3::new(0.0, 0.0, radii_m.z)));
    let bottom = mesh.push_vertex(world_from_local.transform_point3(centre - Vec3::new(0.0, 0.0, radii_m.z)));
    for r in 1..rings {
        let phi = r as f32 / rings as f32 * std::f32::consts::PI;
        let (sp, cp) = phi.sin_cos();
        for k in 0..segments {
            let th = k as f32 / segments as f32 * std::f32::consts::TAU;
            let (st, ct) = th.sin_cos();
            let p = centre + Vec3::new(radii_m.x * sp * ct, radii_m.y * sp * st, radii_m.z * cp);
            mesh.vertices.push(world_from_local.transform_point3(p));
        }
    }
    let ring = |r: u32, k: u32| base + 2 + (r - 1) * segments + (k % segments);
    for k in 0..segments {
        mesh.push_triangle([top, ring(1, k), ring(1, k + 1)], s);
        mesh.push_triangle([bottom, ring(rings - 1, k + 1), ring(rings - 1, k)], s);
        for r in 1..rings - 1 {
            mesh.push_triangle([ring(r, k), ring(r + 1, k), ring(r + 1, k + 1)], s);
            mesh.push_triangle([ring(r, k), ring(r + 1, k + 1), ring(r, k + 1)], s);
        }
    }
}

/// Four wheels (boxes) under a vehicle body of `length` x `width`, radius `r` (local frame).
fn wheels(mesh: &mut SceneMesh, at: Affine3A, length: f32, width: f32, r: f32, s: Surface) {
    for (fx, fy) in [(0.35, 0.5), (0.35, -0.5), (-0.35, 0.5), (-0.35, -0.5)] {
        let c = Vec3::new(fx * length, fy * (width - 0.25), 0.0);
        mesh.push_oriented_box(at, c - Vec3::new(r, 0.12, 0.0), c + Vec3::new(r, 0.12, 2.0 * r), s);
    }
}

/// A car (class car): 4.5 x 1.8 m body from 0.3 m to 1.0 m, a cabin with a flat roof at 1.5 m, wheels.
pub fn car(mesh: &mut SceneMesh, ids: &mut Ids, base: Vec3, yaw_rad: f32) -> u32 {
    let id = ids.fresh();
    let s = Surface::object(SemanticClass::CAR, id);
    let at = pose(base, yaw_rad);
    mesh.push_oriented_box(at, Vec3::new(-2.25, -0.9, 0.3), Vec3::new(2.25, 0.9, 1.0), s);
    mesh.push_oriented_box(at, Vec3::new(-1.4, -0.8, 1.0), Vec3::new(0.9, 0.8, 1.5), s);
    wheels(mesh, at, 4.5, 1.8, 0.3, s);
    id
}

/// A van (class other-vehicle): 5.2 x 2.0 m box body from 0.35 m to 2.3 m with a flat roof.
pub fn van(mesh: &mut SceneMesh, ids: &mut Ids, base: Vec3, yaw_rad: f32) -> u32 {
    let id = ids.fresh();
    let s = Surface::object(SemanticClass::OTHER_VEHICLE, id);
    let at = pose(base, yaw_rad);
    mesh.push_oriented_box(at, Vec3::new(-2.6, -1.0, 0.35), Vec3::new(2.6, 1.0, 2.3), s);
    wheels(mesh, at, 5.2, 2.0, 0.35, s);
    id
}

/// A truck (class truck): a 2.3 m cab and a 9 m box trailer, 2.5 m wide, flat roof at 3.8 m.
pub fn truck(mesh: &mut SceneMesh, ids: &mut Ids, base: Vec3, yaw_rad: f32) -> u32 {
    let id = ids.fresh();
    let s = Surface::object(SemanticClass::TRUCK, id);
    let at = pose(base, yaw_rad);
    mesh.push_oriented_box(at, Vec3::new(3.7, -1.25, 0.5), Vec3::new(6.0, 1.25, 3.2), s);
    mesh.push_oriented_box(at, Vec3::new(-6.0, -1.25, 0.9), Vec3::new(3.5, 1.25, 3.8), s);
    mesh.push_oriented_box(at, Vec3::new(-6.0, -1.0, 0.45), Vec3::new(6.0, 1.0, 0.9), s);
    wheels(mesh, at, 11.0, 2.5, 0.45, s);
    id
}

/// A pedestrian (class person), 1.75 m tall: two legs, a torso and a head.
pub fn pedestrian(mesh: &mut SceneMesh, ids: &mut Ids, base: Vec3, yaw_rad: f32) -> u32 {
    let id = ids.fresh();
    let s = Surface::object(SemanticClass::PERSON, id);
    let at = pose(base, yaw_rad);
    mesh.push_oriented_box(at, Vec3::new(-0.08, 0.03, 0.0), Vec3::new(0.08, 0.18, 0.85), s);
    mesh.push_oriented_box(at, Vec3::new(-0.08, -0.18, 0.0), Vec3::new(0.08, -0.03, 0.85), s);
    mesh.push_oriented_box(at, Vec3::new(-0.12, -0.22, 0.85), Vec3::new(0.12, 0.22, 1.5), s);
    mesh.push_oriented_box(at, Vec3::new(-0.1, -0.09, 1.52), Vec3::new(0.1, 0.09, 1.75), s);
    id
}

/// A pole (class pole): an 8-sided post of `height_m` and 0.08 m radius (street light, post).
pub fn pole(mesh: &mut SceneMesh, ids: &mut Ids, base: Vec3, height_m: f32) -> u32 {
    let id = ids.fresh();
    push_prism(mesh, pose(base, 0.0), 8, 0.08, (-0.2, height_m), Surface::object(SemanticClass::POLE, id));
    id
}

/// A traffic sign: a 2.6 m post (class pole) with a 0.7 m square plate (class traffic-sign) facing
/// along `yaw_rad`; one instance.
pub fn sign(mesh: &mut SceneMesh, ids: &mut Ids, base: Vec3, yaw_rad: f32) -> u32 {
    let id = ids.fresh();
    let at = pose(base, yaw_rad);
    push_prism(mesh, at, 6, 0.04, (-0.2, 2.6), Surface::object(SemanticClass::POLE, id));
    let plate = Surface::object(SemanticClass::TRAFFIC_SIGN, id);
    mesh.push_oriented_box(at, Vec3::new(-0.06, -0.35, 1.9), Vec3::new(-0.04, 0.35, 2.6), plate);
    id
}

/// A tree: a trunk (class trunk) of `trunk_height_m` and radius `trunk_radius_m`, and an ellipsoid
/// crown (class vegetation) of radius `crown_radius_m` resting on the trunk top; one instance.
pub fn tree(
    mesh: &mut SceneMesh,
    ids: &mut Ids,
    base: Vec3,
    trunk_height_m: f32,
    trunk_radius_m: f32,
    crown_radius_m: f32,
) -> u32 {
    let shape = TreeShape {
        crown_base_m: trunk_height_m,
        trunk_radius_m,
        crown_radius_m,
        crown_half_height_m: 0.8 * crown_radius_m,
    };
    shaped_tree(mesh, ids, base, &shape)
}

/// The shape of a broadleaf tree for [`shaped_tree`], metres.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TreeShape {
    /// Height of the crown's bottom (the bare trunk) above the ground point.
    pub crown_base_m: f32,
    /// Trunk radius.
    pub trunk_radius_m: f32,
    /// Horizontal radius of the ellipsoid crown.
    pub crown_radius_m: f32,
    /// Vertical semi-axis of the crown (its height is twice this).
    pub crown_half_height_m: f32,
}

/// A tree of `shape`: an 8-sided trunk (class trunk) from 0.3 m below the ground point up into the
/// crown (to half the crown's lower half), and an ellipsoid crown (class vegetation, 6 x 10
/// facets) whose bottom is `crown_base_m` above the ground point; one instance.
pub fn shaped_tree(mesh: &mut SceneMesh, ids: &mut Ids, base: Vec3, shape: &TreeShape) -> u32 {
    let id = ids.fresh();
    let at = pose(base, 0.0);
    let TreeShape { crown_base_m, trunk_radius_m, crown_radius_m, crown_half_height_m } = *shape;
    push_prism(
        mesh,
        at,
        8,
        trunk_radius_m,
        (-0.3, crown_base_m + 0.5 * crown_half_height_m),
        Surface::object(SemanticClass::TRUNK, id),
    );
    let c = Vec3::new(0.0, 0.0, crown_base_m + crown_half_height_m);
    let r = Vec3::new(crown_radius_m, crown_radius_m, crown_half_height_m);
    push_ellipsoid(mesh, at, c, r, (6, 10), Surface::object(SemanticClass::VEGETATION, id));
    id
}

/// A bush or shrub (class bush, 73: bushes and shrubs are their own class, apart from tree canopy;
/// see [`sim::SemanticClass::BUSH`]): an ellipsoid of radius `radius_m` and height `height_m`, sunk
/// 20 % into the ground so it meets uneven terrain.
pub fn bush(mesh: &mut SceneMesh, ids: &mut Ids, base: Vec3, radius_m: f32, height_m: f32) -> u32 {
    let id = ids.fresh();
    let half = 0.5 * height_m / 0.8;
    let c = Vec3::new(0.0, 0.0, 0.8 * height_m - half);
    push_ellipsoid(
        mesh,
        pose(base, 0.0),
        c,
        Vec3::new(radius_m, radius_m, half),
        (4, 8),
        Surface::object(SemanticClass::BUSH, id),
    );
    id
}

/// A wall (class fence) of `length_m` along its heading, `thickness_m` and `height_m`, centred on `base`.
pub fn wall(mesh: &mut SceneMesh, ids: &mut Ids, base: Vec3, yaw_rad: f32, dims_m: Vec3) -> u32 {
    let id = ids.fresh();
    let h = Vec3::new(0.5 * dims_m.x, 0.5 * dims_m.y, 0.0);
    mesh.push_oriented_box(
        pose(base, yaw_rad),
        -h - Vec3::Z * 0.2,
        h + Vec3::Z * dims_m.z,
        Surface::object(SemanticClass::FENCE, id),
    );
    id
}

/// A guard rail (class fence) from `a` to `b` along the ground (straight, same height at both
/// ends relative to the ground): posts every 2 m and a beam from 0.5 m to 0.8 m.
pub fn guard_rail(mesh: &mut SceneMesh, ids: &mut Ids, a: Vec3, b: Vec3) -> u32 {
    let id = ids.fresh();
    let s = Surface::object(SemanticClass::FENCE, id);
    let d = b - a;
    let len = d.truncate().length();
    let yaw = d.y.atan2(d.x);
    let slope = d.z / len.max(1e-6);
    let n = (len / 2.0).floor() as u32;
    for k in 0..=n {
        let t = k as f32 * 2.0;
        let p = a + Vec3::new(yaw.cos() * t, yaw.sin() * t, slope * t);
        mesh.push_oriented_box(pose(p, yaw), Vec3::new(-0.05, -0.05, -0.2), Vec3::new(0.05, 0.05, 0.8), s);
    }
    // The beam follows the ground slope: a box sheared along its length.
    let at = Affine3A::from_cols(
        Vec3::new(yaw.cos(), yaw.sin(), slope).into(),
        Vec3::new(-yaw.sin(), yaw.cos(), 0.0).into(),
        Vec3::Z.into(),
        a.into(),
    );
    mesh.push_oriented_box(at, Vec3::new(0.0, -0.1, 0.5), Vec3::new(len, -0.05, 0.8), s);
    id
}

/// A building (class building): a box of `dims_m` (x length, y width, z height) standing at `base`,
/// its footprint centred there, sunk 0.5 m into the ground.
pub fn building(mesh: &mut SceneMesh, ids: &mut Ids, base: Vec3, yaw_rad: f32, dims_m: Vec3) -> u32 {
    let id = ids.fresh();
    let h = Vec3::new(0.5 * dims_m.x, 0.5 * dims_m.y, 0.0);
    mesh.push_oriented_box(
        pose(base, yaw_rad),
        -h - Vec3::Z * 0.5,
        h + Vec3::Z * dims_m.z,
        Surface::object(SemanticClass::BUILDING, id),
    );
    id
}

/// A curb stone run (class sidewalk, ground "stuff": instance 0) from `a` to `b` on the ground,
/// `width_m` wide and `height_m` high: a closed box, for islands and kerbs off the terrain grid
/// (street curbs are cut into the terrain grid instead, see the `city` family).
pub fn curb(mesh: &mut SceneMesh, a: Vec3, b: Vec3, width_m: f32, height_m: f32) {
    let d = b - a;
    let len = d.truncate().length();
    let at = pose(a, d.y.atan2(d.x));
    let hw = 0.5 * width_m;
    mesh.push_oriented_box(
        at,
        Vec3::new(0.0, -hw, -0.1),
        Vec3::new(len, hw, height_m),
        Surface::stuff(SemanticClass::SIDEWALK),
    );
}

/// A table (class other-object): a 1.6 x 0.9 m top at 0.75 m on four legs.
pub fn table(mesh: &mut SceneMesh, ids: &mut Ids, base: Vec3, yaw_rad: f32) -> u32 {
    let id = ids.fresh();
    let s = Surface::object(SemanticClass::OTHER_OBJECT, id);
    let at = pose(base, yaw_rad);
    mesh.push_oriented_box(at, Vec3::new(-0.8, -0.45, 0.72), Vec3::new(0.8, 0.45, 0.76), s);
    for (x, y) in [(-0.72, -0.37), (-0.72, 0.37), (0.72, -0.37), (0.72, 0.37)] {
        mesh.push_oriented_box(at, Vec3::new(x - 0.03, y - 0.03, 0.0), Vec3::new(x + 0.03, y + 0.03, 0.72), s);
    }
    id
}

/// A slab or platform (class other-structure) spanning `min..max` (axis-aligned): ceilings, decks,
/// loading docks.
pub fn slab(mesh: &mut SceneMesh, ids: &mut Ids, min: Vec3, max: Vec3) -> u32 {
    let id = ids.fresh();
    mesh.push_box(min, max, Surface::object(SemanticClass::OTHER_STRUCTURE, id));
    id
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn car_has_a_flat_roof_at_1_5_m_and_one_instance() {
        let mut m = SceneMesh::new();
        let mut ids = Ids::default();
        let id = car(&mut m, &mut ids, Vec3::new(10.0, 0.0, 0.0), 0.3);
        assert_eq!(id, 1);
        assert!(m.surfaces.iter().all(|s| s.instance == 1 && s.class == SemanticClass::CAR));
        let (lo, hi) = m.bounds().unwrap();
        assert!((hi.z - 1.5).abs() < 1e-5 && lo.z.abs() < 1e-5);
        let roof = (0..m.len()).filter(|&i| m.triangle_normal(i).z > 0.999 && m.triangle(i)[0].z > 1.49).count();
        assert_eq!(roof, 2);
    }

    #[test]
    fn tree_has_trunk_and_crown_of_the_same_instance() {
        let mut m = SceneMesh::new();
        let mut ids = Ids::default();
        ids.fresh();
        tree(&mut m, &mut ids, Vec3::ZERO, 3.0, 0.2, 2.0);
        let trunk = m.surfaces.iter().filter(|s| s.class == SemanticClass::TRUNK).count();
        let crown = m.surfaces.iter().filter(|s| s.class == SemanticClass::VEGETATION).count();
        assert_eq!(trunk, 8 * 2 + 2 * 6);
        assert_eq!(crown, 10 * 2 + 10 * 2 * 4);
        assert!(m.surfaces.iter().all(|s| s.instance == 2));
        let (_, hi) = m.bounds().unwrap();
        assert!((hi.z - (3.0 + 2.0 * 1.6)).abs() < 1e-4);
    }
}
