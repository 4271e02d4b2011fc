//! Shared helpers of the scenario tests in `tests/tests/`: scan a bundled scene with a rig and
//! classify it, returning the clouds, decisions and scores.

pub mod forests;
pub mod real_files;

use classifier::{Evaluation, FrameInput, method_by_name};
pub use groundtruth_scenario::{LoadedScene, ScanSpec};
use sim::scan::{Frame, scan};

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
    let spec = ScanSpec {
        scene: scene.to_string(),
        rig: rig.to_string(),
        frames: frames as u64,
        speed_m_per_s: f64::from(speed),
        ..ScanSpec::default()
    };
    classify(scan_spec(&spec).0, method)
}

/// Scans what `spec` describes (the scenario crate's one path from a description to the
/// scanner); returns the frames and the rig they were scanned with.
pub fn scan_spec(spec: &ScanSpec) -> (Vec<Frame>, sim::Rig) {
    let scene = spec.load_scene().unwrap_or_else(|e| panic!("{}: {e}", spec.scene));
    let setup = spec.setup(&scene).unwrap_or_else(|e| panic!("{}: {e}", spec.scene));
    let frames = scan(&scene.mesh, &setup.rig, &setup.config).unwrap_or_else(|e| panic!("{}: {e}", spec.scene));
    (frames, setup.rig)
}

/// Scans `scene` (loaded, or a test's mesh through [`LoadedScene::from_mesh`]) with `rig` as
/// `spec` says (its `scene` and `rig` fields unused).
pub fn scan_on(scene: &LoadedScene, rig: &sim::Rig, spec: &ScanSpec) -> Vec<Frame> {
    let setup = spec.setup_with_rig(scene, rig.clone()).unwrap_or_else(|e| panic!("{e}"));
    scan(&scene.mesh, &setup.rig, &setup.config).unwrap_or_else(|e| panic!("{e}"))
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

/// [`scan_on`] on a pool of `threads` worker threads.
pub fn scan_with_threads(threads: usize, scene: &LoadedScene, rig: &sim::Rig, spec: &ScanSpec) -> Vec<Frame> {
    rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(|| scan_on(scene, rig, spec))
}
