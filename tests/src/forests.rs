//! Seed 002's forests measured the paper's way: scan a forest with the nodding UTM-30LX at the
//! paper's mount and count the returns per true class (ground, bushes/shrubs, trunks,
//! branches/leaves), next to the "sensed points" of the paper's Tables I-III. Used by the
//! `forest_shares` example (prints the table) and by `tests/forests.rs` (asserts it).

use sim::scan::{PreparedScene, Scanner};
use sim::{OrderedCloud, Rig, SemanticClass};

/// The four categories of seed 002's hand labels, in table order.
pub const CATEGORIES: [&str; 4] = ["ground", "bushes/shrubs", "trunks", "branches/leaves"];

/// One of the paper's scenes: the bundled forest that stands for it, its rig and its counts.
#[derive(Clone, Copy, Debug)]
pub struct PaperScene {
    /// Bundled scene name (`forest-sparse`, ...).
    pub scene: &'static str,
    /// Rig: a preset name or a rig file relative to the workspace root.
    pub rig: &'static str,
    /// Beams per nod: 200 scans x 721 (180 deg) or x 1081 (270 deg).
    pub beams: usize,
    /// Sensed points per category (Tables I-III), in [`CATEGORIES`] order.
    pub sensed: [u32; 4],
}

impl PaperScene {
    /// Returns of the nod over its beams.
    pub fn returns_fraction(&self) -> f64 {
        f64::from(self.sensed.iter().sum::<u32>()) / self.beams as f64
    }

    /// Share of the returns per category, in [`CATEGORIES`] order.
    pub fn shares(&self) -> [f64; 4] {
        let total = f64::from(self.sensed.iter().sum::<u32>());
        self.sensed.map(|n| f64::from(n) / total)
    }

    /// The scene's rig (the 180 deg rig file for `sparse`, the 270 deg preset for the others).
    pub fn load_rig(&self) -> Rig {
        let path = format!("{}/../{}", env!("CARGO_MANIFEST_DIR"), self.rig);
        let found = if self.rig.ends_with(".toml") { Rig::load(&path) } else { Rig::preset(self.rig) };
        found.unwrap_or_else(|e| panic!("rig {}: {e}", self.rig))
    }
}

/// The paper's three scenes (Tables I, II, III).
pub const PAPER: [PaperScene; 3] = [
    PaperScene {
        scene: "forest-sparse",
        rig: "sim/rigs/nodding-180.toml",
        beams: 200 * 721,
        sensed: [53488, 0, 8324, 7786],
    },
    PaperScene {
        scene: "forest-moderate",
        rig: "utm30lx-nodding",
        beams: 200 * 1081,
        sensed: [74161, 30987, 4483, 32154],
    },
    PaperScene {
        scene: "forest-dense",
        rig: "utm30lx-nodding",
        beams: 200 * 1081,
        sensed: [65192, 67403, 11494, 10314],
    },
];

/// The roof rigs of a vehicle standing in a forest.
pub const ROOF_RIGS: [&str; 5] = ["vlp16-roof", "hdl64e-roof", "os1-64-roof", "os1-128-roof", "lux-roof-4"];

/// Counts of one scanned frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Counts {
    /// Beams (grid cells of the first echo plane).
    pub beams: usize,
    /// Returns (all echo planes).
    pub returns: usize,
    /// Returns per category in [`CATEGORIES`] order; returns of other classes are in `other`.
    pub per_category: [usize; 4],
    /// Returns of any other class.
    pub other: usize,
    /// Ground returns within [`NEAR_M`] (horizontal) of the vehicle origin.
    pub near_ground: usize,
}

/// Horizontal distance from the vehicle origin within which ground counts as "near", metres.
pub const NEAR_M: f32 = 20.0;

impl Counts {
    /// Counts the returns of `cloud` per category.
    pub fn of(cloud: &OrderedCloud) -> Self {
        let mut c = Counts { beams: cloud.rows * cloud.cols, ..Default::default() };
        for i in (0..cloud.len()).filter(|&i| cloud.has_return(i)) {
            c.returns += 1;
            let label = cloud.label[i];
            let category = if cloud.ground[i] {
                0
            } else if label == SemanticClass::BUSH {
                1
            } else if label == SemanticClass::TRUNK {
                2
            } else if label == SemanticClass::VEGETATION {
                3
            } else {
                c.other += 1;
                continue;
            };
            c.per_category[category] += 1;
            if category == 0 && cloud.point_in_vehicle[i].truncate().length() <= NEAR_M {
                c.near_ground += 1;
            }
        }
        c
    }

    /// Returns over beams.
    pub fn returns_fraction(&self) -> f64 {
        self.returns as f64 / self.beams.max(1) as f64
    }

    /// Share of the returns per category.
    pub fn shares(&self) -> [f64; 4] {
        self.per_category.map(|n| n as f64 / self.returns.max(1) as f64)
    }

    /// Share of the returns that are ground.
    pub fn ground_share(&self) -> f64 {
        self.shares()[0]
    }
}

/// Scans bundled `scene` at `seed` with `rig` standing at the ego origin (one frame, default
/// measurement: range noise on, as users get it) and counts the returns.
pub fn measure(scene: &str, rig: &Rig, seed: u64) -> Counts {
    measure_rigs(scene, std::slice::from_ref(rig), seed)[0]
}

/// [`measure`] with each of `rigs` in turn, the scene generated and its caster built once (the
/// same counts as one [`measure`] per rig: the caster is built from the same mesh either way).
pub fn measure_rigs(scene: &str, rigs: &[Rig], seed: u64) -> Vec<Counts> {
    let spec = crate::ScanSpec { scene: scene.to_string(), seed, ..crate::ScanSpec::default() };
    let s = spec.load_scene().unwrap_or_else(|e| panic!("{scene}: {e}"));
    let setups: Vec<_> = rigs
        .iter()
        .map(|rig| spec.setup_with_rig(&s, rig.clone()).unwrap_or_else(|e| panic!("{scene}: {e}")))
        .collect();
    let Some(first) = setups.first() else { return Vec::new() };
    let prepared = PreparedScene::new(&s.mesh, first.config.backend).unwrap_or_else(|e| panic!("{scene}: {e}"));
    setups
        .iter()
        .map(|setup| {
            let scanner = Scanner::with_prepared(&s.mesh, &setup.rig, setup.config.clone(), &prepared)
                .unwrap_or_else(|e| panic!("{scene}: {e}"));
            Counts::of(&scanner.frame(0).cloud)
        })
        .collect()
}

/// How far a measured frame is from the paper: per category the relative error of the share
/// (|measured - paper| / paper; for a category the paper has none, the measured share itself),
/// and the difference of the returns fractions in percentage points.
pub fn deviation(paper: &PaperScene, measured: &Counts) -> ([f64; 4], f64) {
    let (p, m) = (paper.shares(), measured.shares());
    let rel = std::array::from_fn(|k| if p[k] > 0.0 { (m[k] - p[k]).abs() / p[k] } else { m[k] });
    (rel, 100.0 * (measured.returns_fraction() - paper.returns_fraction()))
}
