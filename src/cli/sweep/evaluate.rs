//! One configuration: scan its frames with its rig, measure the point statistics, classify every
//! frame with each method and score it; the result as one row per method.

use std::collections::HashSet;

use anyhow::Context;
use classifier::{Evaluation, FrameInput};
use glam::Vec2;
use groundtruth_scenario::ScanSetup;
use serde_json::Value;
use sim::OrderedCloud;
use sim::scan::{PreparedScene, Scanner};

use super::expand::{Configuration, Space};
use super::results::{bands, num};
use crate::cli::common::LoadedScene;

/// Side of the ground-coverage cells, metres.
const AREA_CELL_M: f32 = 0.5;

/// Point statistics of a configuration's frames (see [`super::results`] for the definitions).
#[derive(Debug, Default)]
pub struct PointStats {
    returns: u64,
    ground_returns: u64,
    ground_cells: HashSet<(i32, i32)>,
    farthest_ground_m: f32,
    ground_rows: Vec<bool>,
    blind_zone_m: f32,
}

impl PointStats {
    fn new() -> Self {
        PointStats { farthest_ground_m: f32::NEG_INFINITY, blind_zone_m: f32::INFINITY, ..Default::default() }
    }

    /// Adds a frame; `body_xy` is the body's position (blind-zone centre) in the vehicle frame.
    fn add(&mut self, cloud: &OrderedCloud, body_xy: Vec2) {
        self.ground_rows.resize(cloud.rows, false);
        let plane = cloud.rows * cloud.cols;
        for i in 0..cloud.len() {
            if !cloud.has_return(i) {
                continue;
            }
            self.returns += 1;
            if !cloud.ground[i] {
                continue;
            }
            self.ground_returns += 1;
            let p = cloud.point_in_vehicle[i];
            self.ground_cells.insert(((p.x / AREA_CELL_M).floor() as i32, (p.y / AREA_CELL_M).floor() as i32));
            self.farthest_ground_m = self.farthest_ground_m.max(cloud.range_m[i]);
            self.blind_zone_m = self.blind_zone_m.min((p.truncate() - body_xy).length());
            if let Some(row) = (i % plane).checked_div(cloud.cols) {
                self.ground_rows[row] = true;
            }
        }
    }

    /// The values of [`super::results::STAT_COLUMNS`].
    fn values(&self) -> [Value; 6] {
        // Through the f32's shortest decimal, so 43.74 reads 43.74, not 43.73999786376953.
        let finite = |x: f32| if x.is_finite() { num(x.to_string().parse().unwrap_or(f64::NAN)) } else { Value::Null };
        [
            Value::from(self.returns),
            Value::from(self.ground_returns),
            num(self.ground_cells.len() as f64 * f64::from(AREA_CELL_M * AREA_CELL_M)),
            finite(self.farthest_ground_m),
            Value::from(self.ground_rows.iter().filter(|&&g| g).count()),
            finite(self.blind_zone_m),
        ]
    }
}

/// Scans configuration `c` of `space` in `scene` (prepared as `prepared`), reusing `cloud`, and
/// returns its rows (one per method, columns as [`super::results::header`]).
pub fn evaluate(
    space: &Space,
    c: &Configuration,
    key: &str,
    scene: &LoadedScene,
    prepared: &PreparedScene,
    cloud: &mut OrderedCloud,
) -> anyhow::Result<Vec<Vec<Value>>> {
    let sweep = &space.sweep;
    let seed = sweep.seeds[c.seed];
    let ScanSetup { config, rig } = space.spec(c)?.setup_with_rig(scene, space.sensor_rig(c)?)?;
    let scanner = Scanner::with_prepared(&scene.mesh, &rig, config, prepared).context("setting up the scan")?;
    let body: Vec<&sim::rig::MountedSensor> =
        rig.sensors.iter().filter(|s| sweep.body == "rig" || s.name == sweep.body).collect();
    let body_xy = body.iter().map(|s| Vec2::new(s.mount.x_m, s.mount.y_m)).fold(Vec2::ZERO, |a, b| a + b)
        / body.len().max(1) as f32;
    let mut methods = sweep
        .methods
        .iter()
        .map(|m| classifier::method_by_name(m, seed).with_context(|| format!("method `{m}`")))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let mut evals = vec![Evaluation::default(); methods.len()];
    let mut stats = PointStats::new();
    for k in 0..sweep.frames {
        scanner.frame_into(k, cloud);
        crate::cli::common::check_device(scanner.caster())?;
        stats.add(cloud, body_xy);
        let input =
            FrameInput { index: k, cloud, world_from_vehicle: Some(scanner.frame_start_pose(k).world_from_vehicle()) };
        for (m, e) in methods.iter_mut().zip(&mut evals) {
            let ground = m.classify(&input).with_context(|| format!("{}: frame {k}", m.name()))?;
            e.add_frame(cloud, &ground);
        }
    }
    let mut fixed = vec![
        Value::from(key),
        Value::from(sweep.scenes[c.scene].as_str()),
        Value::from(sweep.rigs[c.rig].as_str()),
        Value::from(seed),
        Value::from(sweep.body.as_str()),
    ];
    fixed.extend(space.params(c).map(|(_, v)| v.clone()));
    let stat_values = stats.values();
    Ok(sweep
        .methods
        .iter()
        .zip(&evals)
        .map(|(name, e)| {
            let mut row = fixed.clone();
            row.push(Value::from(name.as_str()));
            row.extend(stat_values.iter().cloned());
            let s = e.pooled.scores();
            row.extend([s.acc, s.fpr, s.precision, s.recall, s.f1, s.iou].map(num));
            for b in 0..bands() {
                let conf = e.by_range.get(b).copied().unwrap_or_default();
                let s = conf.scores();
                row.push(Value::from(conf.total()));
                row.extend([s.acc, s.fpr, s.f1].map(num));
            }
            row
        })
        .collect())
}
