//! Shared helpers of the scenario tests in `tests/tests/`: scan a bundled scene with a rig and
//! classify it, returning the clouds, decisions and scores.

pub mod forests;
pub mod real_files;

use classifier::{Evaluation, FrameInput, method_by_name};
use sim::scan::{Frame, ScanConfig, scan};

/// A scanned and classified scenario.
pub struct Scenario {
    /// The scanned frames.
    pub frames: Vec<Frame>,
    /// Per frame, the ground decision of every cell.
    pub decisions: Vec<Vec<bool>>,
    /// Pooled scores.
    pub eval: Evaluation,
}

/// Scans `scene` (bundled name, seed 0) with rig preset `rig` for `frames` frames at `speed` m/s and
/// classifies every frame with `method`.
pub fn run(scene: &str, rig: &str, method: &str, frames: usize, speed: f32) -> Scenario {
    let scene = scenes::load(scene, 0).expect("bundled scene");
    let rig = sim::Rig::preset(rig).expect("rig preset");
    let config = ScanConfig { frames, speed_m_per_s: speed, ego_z_m: scene.ego_ground_z_m, ..ScanConfig::default() };
    let frames = scan(&scene.mesh, &rig, &config).expect("scan");
    classify(frames, method)
}

/// Classifies scanned frames with `method`.
pub fn classify(frames: Vec<Frame>, method: &str) -> Scenario {
    let mut m = method_by_name(method, 0).expect("method");
    let mut eval = Evaluation::default();
    let mut decisions = Vec::new();
    for f in &frames {
        let input = FrameInput { index: f.index, cloud: &f.cloud, world_from_vehicle: Some(f.world_from_vehicle) };
        let d = m.classify(&input).expect("classify");
        eval.add_frame(&f.cloud, &d);
        decisions.push(d);
    }
    Scenario { frames, decisions, eval }
}

/// Every field of every cell of `c` as bits: two clouds are the same bytes iff these are equal.
pub fn cloud_bits(c: &sim::OrderedCloud) -> Vec<u64> {
    let mut v: Vec<u64> = Vec::new();
    v.extend(c.point_in_vehicle.iter().flat_map(|p| p.to_array().map(|x| u64::from(x.to_bits()))));
    v.extend(c.normal.iter().flat_map(|p| p.to_array().map(|x| u64::from(x.to_bits()))));
    v.extend(c.range_m.iter().map(|x| u64::from(x.to_bits())));
    v.extend(c.intensity.iter().map(|x| u64::from(x.to_bits())));
    v.extend(c.time_s.iter().map(|x| x.to_bits()));
    v.extend(c.ring.iter().map(|&x| u64::from(x)));
    v.extend(c.column.iter().map(|&x| u64::from(x)));
    v.extend(c.sensor.iter().map(|&x| u64::from(x)));
    v.extend(c.echo.iter().map(|&x| u64::from(x)));
    v.extend(c.label.iter().map(|x| u64::from(x.0)));
    v.extend(c.instance.iter().map(|&x| u64::from(x)));
    v.extend(c.ground.iter().map(|&x| u64::from(x)));
    v
}

/// Scans `mesh` with `rig` on a pool of `threads` worker threads.
pub fn scan_with_threads(threads: usize, mesh: &sim::SceneMesh, rig: &sim::Rig, config: &ScanConfig) -> Vec<Frame> {
    rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(|| scan(mesh, rig, config).unwrap())
}
