//! `forest-sparse`, `forest-moderate`, `forest-dense`: seed 002's three scenes (McDaniel et al.),
//! made so that one nod of its UTM-30LX at the paper's mount sees what the paper's did. Tables
//! I-III count the sensed points per true class; as shares of the returns, and returns over beams
//! (200 scans x 721 beams at 180 deg for `sparse`, x 1081 at 270 deg for the others):
//!
//! | scene    | returns | ground | bushes/shrubs | trunks | branches/leaves |
//! |----------|---------|--------|---------------|--------|-----------------|
//! | sparse   | 48.2 %  | 76.9 % | 0 %           | 12.0 % | 11.2 %          |
//! | moderate | 65.5 %  | 52.3 % | 21.9 %        | 3.2 %  | 22.7 %          |
//! | dense    | 71.4 %  | 42.2 % | 43.7 %        | 7.4 %  | 6.7 %           |
//!
//! # The scenes
//! - `sparse`, MIT's Killian Court: a mown lawn, a 3 m path through the ego origin along x, and
//!   big old trees planted about 9 m apart in rows from the path (trunks 0.5-0.8 m across, crowns
//!   pruned up to 7.5-11.5 m, tall, 5 m across); no bushes. The ego stands on a low, round rise
//!   (`rise_m`: the lawn falls 1.2 m by 19 m and 2.5 m by 30 m): on open flat ground this pitch range (-75..+55 deg) already gives
//!   returns on 54.7 % of the beams, above the paper's 48.2 %; the rise lets the far lawn drop out
//!   of the beams' reach, as on a slightly domed lawn.
//! - `moderate`, an open arboretum: deciduous trees about 10 m apart with broad crowns from about
//!   4.3 m up, low bushes (0.5-1.2 m) and shrubs in the open ground, a 4.5 m forest track with
//!   2.5 m verges where only shrubs grow.
//! - `dense`, a cluttered arboretum: young trees about 5 m apart with small, flat crowns from about
//!   4.3 m up, bushes (0.9-2.2 m) and shrubs everywhere up to a 5 m forest track with 1.5 m verges.
//!
//! Every forest has a forest track (class other-ground, following the terrain) through the ego
//! origin along +x, free of trunks, bushes and crowns lower than [`OVERHANG_MIN_M`], and a clearing
//! around the origin free of trees and bushes, so a vehicle can stand there. Trees and bushes are
//! laid out on jittered grids from the verges' outer edges (`stratified`): planted and
//! competing trees are spaced more evenly than random points, and the nearest ones stand at a
//! steady distance from the ego, which keeps the shares steady from seed to seed.
//!
//! # Measured
//! `cargo run --release -p gt-tests --example forest_shares -- --seeds 0,1,2,3,4` (default
//! measurement, range noise on; `tests/tests/forests.rs` asserts seeds 0-2 in CI):
//!
//! | scene    | seed | returns | ground | bushes/shrubs | trunks | branches/leaves |
//! |----------|------|---------|--------|---------------|--------|-----------------|
//! | sparse   | 0    | 60.1 %  | 77.2 % | 0 %           | 12.1 % | 10.7 %          |
//! | sparse   | 1    | 61.1 %  | 76.5 % | 0 %           | 12.9 % | 10.6 %          |
//! | sparse   | 2    | 58.6 %  | 78.1 % | 0 %           | 11.3 % | 10.6 %          |
//! | sparse   | 3    | 61.1 %  | 75.4 % | 0 %           | 10.7 % | 13.9 %          |
//! | sparse   | 4    | 59.9 %  | 77.3 % | 0 %           | 11.4 % | 11.3 %          |
//! | moderate | 0    | 75.1 %  | 54.6 % | 20.8 %        | 2.7 %  | 21.9 %          |
//! | moderate | 1    | 76.5 %  | 52.1 % | 22.6 %        | 3.1 %  | 22.2 %          |
//! | moderate | 2    | 74.5 %  | 52.7 % | 18.9 %        | 3.3 %  | 25.1 %          |
//! | moderate | 3    | 77.0 %  | 51.7 % | 22.0 %        | 3.3 %  | 23.0 %          |
//! | moderate | 4    | 77.2 %  | 51.3 % | 22.1 %        | 3.1 %  | 23.5 %          |
//! | dense    | 0    | 77.5 %  | 48.7 % | 37.5 %        | 7.6 %  | 6.2 %           |
//! | dense    | 1    | 77.8 %  | 46.9 % | 39.6 %        | 6.8 %  | 6.7 %           |
//! | dense    | 2    | 77.3 %  | 46.9 % | 37.6 %        | 8.3 %  | 7.2 %           |
//! | dense    | 3    | 78.5 %  | 48.1 % | 37.5 %        | 7.5 %  | 6.9 %           |
//! | dense    | 4    | 78.3 %  | 47.3 % | 39.2 %        | 6.2 %  | 7.3 %           |
//!
//! Over seeds 0-39, 118 of the 120 nods have every share within 20 % of the paper's (relative)
//! and the returns within 15 points; the two others miss by a little (sparse seed 3: canopy
//! 13.9 %, 24 % off; moderate seed 32: trunks 2.5 %, 22 % off). The returns stay 6-13 points above
//! the paper's: the sensor model returns every beam that meets a surface within 30 m.
//!
//! A vehicle on the track sees ground with every roof rig (seeds 0-4, share of its returns that
//! are ground, sparse / moderate / dense): `hdl64e-roof` 70-72 / 45-49 / 30-33 %, `os1-128-roof`
//! 44-45 / 28-30 / 24-26 %, `lux-roof-4` 56-61 / 36-41 / 26-32 %, `os1-64-roof` 38-39 / 20-22 /
//! 14-16 %, `vlp16-roof` 37-38 / 18-21 / 14-15 % (the 16 and 64 beam sensors, +-15 and +-16.6 deg,
//! see the ground of the dense forest mostly along the track). A landing for them, `clearing_m =
//! 12`, gives `vlp16-roof` 25 % and `os1-64-roof` 26 % ground on `forest-dense`, but opens the
//! paper's dense scene around the nodding sensor too (its ground share 56 %, the paper's 42 %).

use glam::Vec3;
use rand::RngExt;
use rand_xoshiro::Xoshiro256PlusPlus;
use serde::Deserialize;
use sim::SceneMesh;
use sim::{SemanticClass, Surface};

use super::{Family, Generated, rng};
use crate::error::{SceneError, check};
use crate::grid::{Grid, axis};
use crate::noise::Fbm;
use crate::objects::{self, Ids, TreeShape};

/// Most objects (trees + bushes + shrubs) a forest may hold (about 4 M triangles).
const MAX_OBJECTS: f32 = 40_000.0;

/// Crowns whose bottom is at least this high above the ground may reach over the track and the
/// clearing (a forest road's clearance); lower crowns stay out of them like trunks and bushes.
pub const OVERHANG_MIN_M: f32 = 3.5;

/// Radius (standard deviation) of the Gaussian rise the ego stands on, metres.
const RISE_SIGMA_M: f32 = 25.0;

/// Radius around the ego origin kept free of shrubs (low enough to grow in the clearing), metres:
/// the footprint of seed 002's small robot.
const SHRUB_CLEARING_M: f32 = 0.6;

/// Space kept between a trunk or bush and the track edge or the clearing, metres.
const MARGIN_M: f32 = 0.3;

/// Parameters shared by the three forest families; every field defaults to its preset's value
/// (listed as sparse / moderate / dense).
#[derive(Deserialize, Debug, Clone, Default)]
#[serde(default, deny_unknown_fields)]
pub struct Params {
    /// Side of the square terrain, metres (50 ..= 600; 240 / 160 / 120).
    pub size_m: Option<f32>,
    /// Peak height of the terrain relief, metres (0 ..= 5; 0.3 / 0.5 / 0.6).
    pub relief_m: Option<f32>,
    /// Trees per hectare (0 ..= 2000; 115 / 100 / 370).
    pub trees_per_ha: Option<f32>,
    /// Bushes per hectare (0 ..= 10000; 0 / 3400 / 7600).
    pub bushes_per_ha: Option<f32>,
    /// Shrubs (0.2-0.6 m radius, 0.3-0.9 m high) per hectare (0 ..= 10000; 0 / 1400 / 4400).
    pub shrubs_per_ha: Option<f32>,
    /// Radius around the ego origin kept free of trunks, bushes and low crowns, metres (shrubs grow
    /// in it; 0.5 ..= 20; 4 / 2.3 / 2.2).
    pub clearing_m: Option<f32>,
    /// Width of the forest track through the ego origin along x (a dirt track, class
    /// other-ground, following the terrain, free of trunks, bushes and low crowns), metres
    /// (0 ..= 12, 0 = no track; 3 / 4.5 / 5).
    pub track_width_m: Option<f32>,
    /// Width of the verge on each side of the track where only shrubs grow (no trees or bushes;
    /// none without a track), metres (0 ..= 20; 0 / 2.5 / 1.5).
    pub verge_m: Option<f32>,
    /// Height of the low, round rise the ego stands on top of: the terrain falls away from the
    /// origin as `rise_m * (exp(-r^2 / (2 * 25^2)) - 1)` (r metres from the origin: a quarter of it
    /// by 19 m, half by 30 m), on top of the relief, metres (0 ..= 10; 5 / 0 / 0).
    pub rise_m: Option<f32>,
    /// Mean height of the crowns' bottom above the ground, metres (1 ..= 15; each tree 0.8-1.2
    /// times it; 9.5 / 4.3 / 4.3).
    pub crown_base_m: Option<f32>,
    /// Mean crown radius, metres (0.5 ..= 10; each tree 0.8-1.2 times it; 2.6 / 3.6 / 1.02).
    pub crown_radius_m: Option<f32>,
    /// Mean trunk radius, metres (0.05 ..= 1.5; each tree 0.75-1.25 times it; 0.32 / 0.28 / 0.295).
    pub trunk_radius_m: Option<f32>,
    /// Mean bush height, metres (0.3 ..= 4; each bush 0.6-1.4 times it, radius 0.5-1.1 times
    /// it; 1.2 / 0.85 / 1.55).
    pub bush_height_m: Option<f32>,
    /// Crown height (twice its vertical semi-axis) over crown diameter (0.3 ..= 3; 1.3 / 0.8 / 0.55).
    pub crown_aspect: Option<f32>,
    /// How far trees stray from a regular planting grid, in cells (0 = an orchard, 1 = anywhere in
    /// their cell; 0 ..= 1; 0.4 / 0.2 / 0.22).
    pub tree_jitter: Option<f32>,
}

/// Resolved forest parameters (see [`Params`] for the meaning of each).
#[derive(Debug, Clone, Copy)]
struct Resolved {
    size_m: f32,
    relief_m: f32,
    trees_per_ha: f32,
    bushes_per_ha: f32,
    shrubs_per_ha: f32,
    clearing_m: f32,
    track_width_m: f32,
    verge_m: f32,
    rise_m: f32,
    crown_base_m: f32,
    crown_radius_m: f32,
    trunk_radius_m: f32,
    bush_height_m: f32,
    crown_aspect: f32,
    tree_jitter: f32,
}

/// The three presets.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Preset {
    /// `forest-sparse`.
    Sparse,
    /// `forest-moderate`.
    Moderate,
    /// `forest-dense`.
    Dense,
}

impl Preset {
    fn defaults(self) -> Resolved {
        match self {
            // MIT's Killian Court: a mown lawn on a low rise, a path, and big old trees (crowns
            // pruned up to 7-12 m, trunks 0.4-0.8 m across) planted about 9 m apart; no bushes.
            Preset::Sparse => Resolved {
                size_m: 240.0,
                relief_m: 0.3,
                trees_per_ha: 115.0,
                bushes_per_ha: 0.0,
                shrubs_per_ha: 0.0,
                clearing_m: 4.0,
                track_width_m: 3.0,
                verge_m: 0.0,
                rise_m: 5.0,
                crown_base_m: 9.5,
                crown_radius_m: 2.6,
                trunk_radius_m: 0.32,
                bush_height_m: 1.2,
                crown_aspect: 1.3,
                tree_jitter: 0.4,
            },
            // An open arboretum: deciduous trees about 10 m apart with broad crowns from about
            // 4 m up, low bushes (0.5-1.2 m) and shrubs in the open ground, a track through it.
            Preset::Moderate => Resolved {
                size_m: 160.0,
                relief_m: 0.5,
                trees_per_ha: 100.0,
                bushes_per_ha: 3400.0,
                shrubs_per_ha: 1400.0,
                clearing_m: 2.3,
                track_width_m: 4.5,
                verge_m: 2.5,
                rise_m: 0.0,
                crown_base_m: 4.3,
                crown_radius_m: 3.6,
                trunk_radius_m: 0.28,
                bush_height_m: 0.85,
                crown_aspect: 0.8,
                tree_jitter: 0.2,
            },
            // A cluttered arboretum: young trees about 5 m apart with small, flat crowns from
            // about 4 m up, and bushes (0.9-2 m) and shrubs everywhere up to the track.
            Preset::Dense => Resolved {
                size_m: 120.0,
                relief_m: 0.6,
                trees_per_ha: 370.0,
                bushes_per_ha: 7600.0,
                shrubs_per_ha: 4400.0,
                clearing_m: 2.2,
                track_width_m: 5.0,
                verge_m: 1.5,
                rise_m: 0.0,
                crown_base_m: 4.3,
                crown_radius_m: 1.02,
                trunk_radius_m: 0.295,
                bush_height_m: 1.55,
                crown_aspect: 0.55,
                tree_jitter: 0.22,
            },
        }
    }
}

/// Points of a stratified (jittered grid) sample over `[-reach, reach]^2` at `per_ha` points per
/// hectare, laid out from the track: square cells of side `c` with centres at
/// `x = (i + 1/2) c` and `|y| = y0 + (j + 1/2) c` on both sides of the track (`y0`: the track's
/// half width plus its verge), one point per cell at its centre plus a uniform offset of up to
/// `jitter / 2` cells in x and y (`jitter` 1: anywhere in the cell). Planted and competing trees
/// and bushes are spaced more evenly than independent uniform points, the first row stands at a
/// steady distance from the track, and the counts near the origin vary much less from seed to seed.
fn stratified(r: &mut Xoshiro256PlusPlus, per_ha: f32, reach: f32, y0: f32, jitter: f32) -> Vec<(f32, f32)> {
    if per_ha <= 0.0 {
        return Vec::new();
    }
    let cell = 100.0 / per_ha.sqrt();
    let n = (reach / cell).ceil() as i32;
    let mut out = Vec::with_capacity((4 * n * n) as usize);
    for side in [-1.0f32, 1.0] {
        for j in 0..n {
            for i in -n..n {
                let x = (i as f32 + 0.5 + jitter * r.random_range(-0.5..0.5f32)) * cell;
                let y = side * (y0 + (j as f32 + 0.5 + jitter * r.random_range(-0.5..0.5f32)) * cell);
                if x.abs() < reach && y.abs() < reach {
                    out.push((x, y));
                }
            }
        }
    }
    out
}

impl Params {
    fn resolve(&self, preset: Preset) -> Resolved {
        let d = preset.defaults();
        Resolved {
            size_m: self.size_m.unwrap_or(d.size_m),
            relief_m: self.relief_m.unwrap_or(d.relief_m),
            trees_per_ha: self.trees_per_ha.unwrap_or(d.trees_per_ha),
            bushes_per_ha: self.bushes_per_ha.unwrap_or(d.bushes_per_ha),
            shrubs_per_ha: self.shrubs_per_ha.unwrap_or(d.shrubs_per_ha),
            clearing_m: self.clearing_m.unwrap_or(d.clearing_m),
            track_width_m: self.track_width_m.unwrap_or(d.track_width_m),
            verge_m: self.verge_m.unwrap_or(d.verge_m),
            rise_m: self.rise_m.unwrap_or(d.rise_m),
            crown_base_m: self.crown_base_m.unwrap_or(d.crown_base_m),
            crown_radius_m: self.crown_radius_m.unwrap_or(d.crown_radius_m),
            trunk_radius_m: self.trunk_radius_m.unwrap_or(d.trunk_radius_m),
            bush_height_m: self.bush_height_m.unwrap_or(d.bush_height_m),
            crown_aspect: self.crown_aspect.unwrap_or(d.crown_aspect),
            tree_jitter: self.tree_jitter.unwrap_or(d.tree_jitter),
        }
    }

    fn check(&self, preset: Preset) -> Result<(), SceneError> {
        let r = self.resolve(preset);
        check("size_m", r.size_m, 50.0, 600.0)?;
        check("relief_m", r.relief_m, 0.0, 5.0)?;
        check("trees_per_ha", r.trees_per_ha, 0.0, 2000.0)?;
        check("bushes_per_ha", r.bushes_per_ha, 0.0, 10000.0)?;
        check("shrubs_per_ha", r.shrubs_per_ha, 0.0, 10000.0)?;
        check("clearing_m", r.clearing_m, 0.5, 20.0)?;
        check("track_width_m", r.track_width_m, 0.0, 12.0)?;
        check("verge_m", r.verge_m, 0.0, 20.0)?;
        check("rise_m", r.rise_m, 0.0, 10.0)?;
        check("crown_base_m", r.crown_base_m, 1.0, 15.0)?;
        check("crown_radius_m", r.crown_radius_m, 0.5, 10.0)?;
        check("trunk_radius_m", r.trunk_radius_m, 0.05, 1.5)?;
        check("bush_height_m", r.bush_height_m, 0.3, 4.0)?;
        check("crown_aspect", r.crown_aspect, 0.3, 3.0)?;
        check("tree_jitter", r.tree_jitter, 0.0, 1.0)?;
        let objects = (r.trees_per_ha + r.bushes_per_ha + r.shrubs_per_ha) * r.size_m * r.size_m / 10_000.0;
        if objects > MAX_OBJECTS {
            return Err(SceneError::invalid(
                "params.trees_per_ha + bushes_per_ha + shrubs_per_ha",
                objects.round(),
                format!("at most {MAX_OBJECTS} objects over size_m^2 (lower the densities or size_m)"),
            ));
        }
        Ok(())
    }

    fn generate(&self, preset: Preset, seed: u64) -> Generated {
        let p = self.resolve(preset);
        let half = 0.5 * p.size_m;
        let fbm = Fbm { seed: seed ^ 0xf0_7e57, wavelength_m: 40.0, amplitude_m: p.relief_m, octaves: 4 };
        let z0 = fbm.at(0.0, 0.0);
        // Terrain shifted so the ground under the ego origin is at z = 0.
        let rise_m = p.rise_m;
        let height = move |x: f32, y: f32| {
            let fall = rise_m * ((-(x * x + y * y) / (2.0 * RISE_SIGMA_M * RISE_SIGMA_M)).exp() - 1.0);
            fbm.at(x, y) - z0 + fall
        };
        let mut mesh = SceneMesh::new();
        let track_half = 0.5 * p.track_width_m;
        let edges: Vec<f32> = if track_half > 0.0 { vec![-track_half, track_half] } else { Vec::new() };
        let xs = axis(half, 40.0, 0.5, 1.0, &[], &[]);
        let ys = axis(half, 40.0, 0.5, 1.0, &edges, &[]);
        let track = Surface::stuff(SemanticClass::OTHER_GROUND);
        let terrain = Surface::stuff(SemanticClass::TERRAIN);
        Grid::new(xs, ys).push(&mut mesh, height, |c| Some(if c.y.abs() < track_half { track } else { terrain }));
        // Whether a footprint of radius `r` at (x, y) stays `verge` off the track and out of the
        // clearing.
        let free = |x: f32, y: f32, r: f32, verge: f32, clearing: f32| {
            let off_track = track_half <= 0.0 || y.abs() > track_half + verge + r;
            off_track && x.hypot(y) > clearing + r
        };
        let mut ids = Ids::default();
        let reach = half - 3.0;
        // Trees and bushes are laid out from the verge's outer edge, shrubs from the track's.
        let edge = if track_half > 0.0 { track_half + p.verge_m } else { 0.0 };
        let mut r = rng(seed, 13);
        let vary =
            |r: &mut Xoshiro256PlusPlus, mean: f32, spread: f32| mean * r.random_range(1.0 - spread..1.0 + spread);
        for (x, y) in stratified(&mut r, p.trees_per_ha, reach, edge, p.tree_jitter) {
            let crown_radius_m = vary(&mut r, p.crown_radius_m, 0.2);
            let shape = TreeShape {
                crown_base_m: vary(&mut r, p.crown_base_m, 0.2),
                trunk_radius_m: vary(&mut r, p.trunk_radius_m, 0.25),
                crown_radius_m,
                crown_half_height_m: p.crown_aspect * crown_radius_m,
            };
            let reach_over = if shape.crown_base_m >= OVERHANG_MIN_M { shape.trunk_radius_m } else { crown_radius_m };
            if free(x, y, reach_over + MARGIN_M, p.verge_m, p.clearing_m) {
                objects::shaped_tree(&mut mesh, &mut ids, Vec3::new(x, y, height(x, y)), &shape);
            }
        }
        for (x, y) in stratified(&mut r, p.bushes_per_ha, reach, edge, 1.0) {
            let h = vary(&mut r, p.bush_height_m, 0.4);
            let rad = h * r.random_range(0.5..1.1f32);
            if free(x, y, rad + MARGIN_M, p.verge_m, p.clearing_m) {
                objects::bush(&mut mesh, &mut ids, Vec3::new(x, y, height(x, y)), rad, h);
            }
        }
        for (x, y) in stratified(&mut r, p.shrubs_per_ha, reach, track_half, 1.0) {
            let rad = r.random_range(0.2..0.6f32);
            let h = r.random_range(0.3..0.9f32);
            if free(x, y, rad + MARGIN_M, 0.0, SHRUB_CLEARING_M) {
                objects::bush(&mut mesh, &mut ids, Vec3::new(x, y, height(x, y)), rad, h);
            }
        }
        Generated { mesh, ego_ground_z_m: 0.0, ids }
    }
}

macro_rules! preset_family {
    ($name:ident, $preset:expr, $doc:literal) => {
        #[doc = $doc]
        #[derive(Deserialize, Debug, Clone, Default)]
        #[serde(transparent)]
        pub struct $name(pub Params);

        impl Family for $name {
            fn validate(&self) -> Result<(), SceneError> {
                self.0.check($preset)
            }
            fn build(&self, seed: u64) -> Generated {
                self.0.generate($preset, seed)
            }
        }
    };
}

preset_family!(
    Sparse,
    Preset::Sparse,
    "`forest-sparse`: a lawn on a low rise with rows of big old trees, a path, no bushes."
);
preset_family!(
    Moderate,
    Preset::Moderate,
    "`forest-moderate`: an open arboretum, trees, bushes and shrubs, a forest track."
);
preset_family!(
    Dense,
    Preset::Dense,
    "`forest-dense`: a cluttered arboretum, young trees over bushes and shrubs, a forest track."
);
