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
