//! Ground classification after McDaniel, Nishihata, Brooks and Iagnemma, *Ground Plane
//! Identification Using LIDAR in Forested Environments* (ICRA 2010, seed 002): a local minimum-z
//! filter followed by a linear SVM on eight geometric features.
//!
//! Data flow for one [`sim::OrderedCloud`] (vehicle frame, z = 0 on the ground under the vehicle
//! origin; every return of every echo plane takes part):
//!
//! 1. [`columns`] (stage 1): 0.5 m x 0.5 m columns, the lowest return of each is its candidate.
//! 2. [`features`]: f1-f6 over the candidate's 3 x 3 column neighbourhood; [`pyramid`]: f7, the
//!    pyramid filter; [`ray_trace`]: f8, the beams passing under the candidate's voxel, from the
//!    sensor origins of [`crate::sensor_origin`].
//! 3. [`svm`]: a linear SVM (C = 100) on standardised features, trained by dual coordinate descent
//!    ([`train`]); [`model`]: the model and its JSON file.
//! 4. Whole clouds ([`McDaniel::classify`]): a return is ground iff its column's candidate is
//!    classified ground and the return lies at most [`McDanielParams::ground_height_m`] above the
//!    candidate. Cells without a return (and returns beyond the stage 1 extent) are not ground.
//!
//! [`candidates`] gives the per-candidate features with their true label and class for the paper's
//! evaluation, [`roc`] the ROC curve and its area.

pub mod columns;
pub mod features;
pub mod model;
pub mod pyramid;
pub mod ray_trace;
pub mod roc;
pub mod svm;

use std::time::Instant;

use glam::Vec3;
use serde::{Deserialize, Serialize};

pub use columns::Columns;
pub use model::{MODEL_FORMAT, MODEL_VERSION, McDanielModel, ModelError};
pub use roc::{auc, roc_curve};
pub use svm::{LinearSvm, SvmParams, train_linear_svm};

use crate::error::{ClassifyError, Result};

/// Number of features.
pub const FEATURE_COUNT: usize = 8;

/// The feature names, in order, as the model file lists them.
pub const FEATURE_NAMES: [&str; FEATURE_COUNT] = [
    "f1_occupied_columns",
    "f2_min_z_minus_z",
    "f3_z",
    "f4_mean_z",
    "f5_normal_z",
    "f6_plane_rss",
    "f7_pyramid_count",
    "f8_ray_trace_score",
];

/// The bundled default model: trained on the three bundled forests (see `classifier/models/`).
pub const DEFAULT_MODEL_JSON: &str = include_str!("../../models/mcdaniel-forest.json");

/// How the features are computed. Stored in the model file, since a model only fits features
/// computed the same way.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FeatureParams {
    /// Column and voxel edge, metres (0.05 ..= 5; the paper: 0.5).
    pub cell_m: f32,
    /// Depth of the pyramid filter f7 in voxel layers below the apex (1 ..= 32; default 4, i.e.
    /// 2 m at 0.5 m voxels).
    pub pyramid_layers: u32,
    /// Stage 1 takes returns with `|x|, |y| <= max_extent_m` only (1 ..= 1000 m, at most 4096
    /// columns across: `2 * max_extent_m / cell_m <= 4096`); default 200 m.
    pub max_extent_m: f32,
}

impl Default for FeatureParams {
    fn default() -> Self {
        Self { cell_m: 0.5, pyramid_layers: 4, max_extent_m: 200.0 }
    }
}

impl FeatureParams {
    /// Checks every field, naming it and its allowed range.
    pub fn validate(&self) -> Result<()> {
        if !(self.cell_m.is_finite() && (0.05..=5.0).contains(&self.cell_m)) {
            return Err(ClassifyError::invalid("cell_m", self.cell_m, "0.05 ..= 5"));
        }
        if !(1..=32).contains(&self.pyramid_layers) {
            return Err(ClassifyError::invalid("pyramid_layers", self.pyramid_layers, "1 ..= 32"));
        }
        if !(self.max_extent_m.is_finite() && (1.0..=1000.0).contains(&self.max_extent_m)) {
            return Err(ClassifyError::invalid("max_extent_m", self.max_extent_m, "1 ..= 1000"));
        }
        if 2.0 * self.max_extent_m / self.cell_m > 4096.0 {
            return Err(ClassifyError::invalid(
                "max_extent_m",
                self.max_extent_m,
                "at most 2048 columns each side: max_extent_m <= 2048 * cell_m",
            ));
        }
        Ok(())
    }
}

/// The true class of a candidate, after the paper's four hand-labelled categories.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TrueClass {
    /// Ground truth ground (any ground class).
    Ground,
    /// Bushes and shrubs (73).
    Bush,
    /// Tree trunks (71).
    Trunk,
    /// Tree branches and leaves (70 vegetation).
    Canopy,
    /// Anything else.
    Other,
}

impl TrueClass {
    /// The class of a return from its ground flag and semantic label.
    pub fn of(ground: bool, label: sim::SemanticClass) -> Self {
        if ground {
            TrueClass::Ground
        } else {
            match label.0 {
                73 => TrueClass::Bush,
                71 => TrueClass::Trunk,
                70 => TrueClass::Canopy,
                _ => TrueClass::Other,
            }
        }
    }

    /// Every class, in table order.
    pub const ALL: [TrueClass; 5] =
        [TrueClass::Ground, TrueClass::Bush, TrueClass::Trunk, TrueClass::Canopy, TrueClass::Other];

    /// Lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            TrueClass::Ground => "ground",
            TrueClass::Bush => "bush",
            TrueClass::Trunk => "trunk",
            TrueClass::Canopy => "canopy",
            TrueClass::Other => "other",
        }
    }
}

/// The candidates of one frame with their features and truth, for training and evaluation.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CandidateSet {
    /// How the features were computed.
    pub feature_params: FeatureParams,
    /// Per candidate, its cloud cell.
    pub cell: Vec<u32>,
    /// Per candidate, its point (vehicle frame).
    pub point_in_vehicle: Vec<Vec3>,
    /// Per candidate, f1-f8.
    pub features: Vec<[f32; FEATURE_COUNT]>,
    /// Per candidate, whether its return is ground truth ground.
    pub ground: Vec<bool>,
    /// Per candidate, its true class.
    pub class: Vec<TrueClass>,
}

impl CandidateSet {
    /// Number of candidates.
    pub fn len(&self) -> usize {
        self.cell.len()
    }

    /// Whether there is no candidate.
    pub fn is_empty(&self) -> bool {
        self.cell.is_empty()
    }
}

/// Wall-clock times of the stages of the last frame, seconds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct McDanielTimes {
    /// Sensor origins (estimation, or the known ones checked).
    pub origins_s: f64,
    /// Stage 1: columns and min-z candidates.
    pub stage1_s: f64,
    /// Features f1-f6.
    pub features_s: f64,
    /// Feature f7 (pyramid filter).
    pub pyramid_s: f64,
    /// Feature f8 (ray tracing).
    pub ray_trace_s: f64,
    /// SVM decision values.
    pub svm_s: f64,
    /// Decisions of every return from its column's candidate.
    pub propagate_s: f64,
}

impl McDanielTimes {
    /// `(stage name, seconds)` pairs in pipeline order.
    pub fn named(&self) -> Vec<(&'static str, f64)> {
        vec![
            ("origins", self.origins_s),
            ("stage1", self.stage1_s),
            ("f1-f6", self.features_s),
            ("f7", self.pyramid_s),
            ("f8", self.ray_trace_s),
            ("svm", self.svm_s),
            ("propagate", self.propagate_s),
        ]
    }

    /// Sum of the stages.
    pub fn total_s(&self) -> f64 {
        self.named().iter().map(|x| x.1).sum()
    }
}

/// Stage 1 and the eight features of `cloud`: the columns and, per candidate, f1-f8. The cloud must
/// be consistent and at least 2 x 2 cells, as for every method ([`crate::error::check_cloud`]). `origins`
/// gives the sensor origins by sensor id (vehicle frame); `None` estimates them
/// ([`crate::sensor_origin`]). Fills `times` (all but `svm_s` and `propagate_s`).
pub fn extract_features(
    cloud: &sim::OrderedCloud,
    params: &FeatureParams,
    origins: Option<&[Vec3]>,
    times: &mut McDanielTimes,
) -> Result<(Columns, Vec<[f32; FEATURE_COUNT]>)> {
    params.validate()?;
    crate::error::check_cloud(cloud)?;
    let t = Instant::now();
    let origins = crate::sensor_origin::origins_for_cloud(cloud, origins)?;
    times.origins_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let columns = Columns::build(cloud, params);
    times.stage1_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let local = features::all_local_features(&columns);
    times.features_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let f7 = pyramid::all_pyramid_counts(&columns, params.pyramid_layers);
    times.pyramid_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let f8 = ray_trace::ray_trace_counts(cloud, &columns, &origins);
    times.ray_trace_s = t.elapsed().as_secs_f64();
    let feats = (0..columns.len())
        .map(|k| {
            let l = local[k];
            [l[0], l[1], l[2], l[3], l[4], l[5], f7[k] as f32, f8[k] as f32]
        })
        .collect();
    Ok((columns, feats))
}

/// The candidates of `cloud` with their features, true label and class (for training and the
/// paper's evaluation). `origins` as in [`extract_features`].
pub fn candidates(cloud: &sim::OrderedCloud, params: &FeatureParams, origins: Option<&[Vec3]>) -> Result<CandidateSet> {
    let (columns, features) = extract_features(cloud, params, origins, &mut McDanielTimes::default())?;
    let ground: Vec<bool> = columns.cell.iter().map(|&c| cloud.ground[c as usize]).collect();
    let class =
        columns.cell.iter().map(|&c| TrueClass::of(cloud.ground[c as usize], cloud.label[c as usize])).collect();
    Ok(CandidateSet {
        feature_params: params.clone(),
        cell: columns.cell,
        point_in_vehicle: columns.point_in_vehicle,
        features,
        ground,
        class,
    })
}

/// The decision value of every candidate of `set` under `model`.
pub fn decision_values(model: &McDanielModel, set: &CandidateSet) -> Vec<f64> {
    set.features.iter().map(|f| model.decision_value(f)).collect()
}

/// Training parameters of [`train`].
#[derive(Clone, Debug, PartialEq)]
pub struct TrainParams {
    /// The SVM solver's parameters (C = 100 by default).
    pub svm: SvmParams,
    /// What the model is trained on (free-form, stored in the model file).
    pub trained_on: serde_json::Value,
}

impl Default for TrainParams {
    fn default() -> Self {
        Self { svm: SvmParams::default(), trained_on: serde_json::Value::Null }
    }
}

/// Trains a model on the candidates of `sets` (all with the same feature parameters): features
/// standardised by the training set's mean and standard deviation (0 -> 1), then the linear SVM.
/// Errors ([`ClassifyError::TrainingSet`]) when there are no ground or no non-ground candidates.
pub fn train(sets: &[CandidateSet], params: &TrainParams) -> Result<McDanielModel> {
    train_with_report(sets, params).map(|(model, _)| model)
}

/// [`train`], also returning the solver's outer iterations and whether it reached its tolerance
/// (false: it stopped at [`SvmParams::max_iter`]).
pub fn train_with_report(sets: &[CandidateSet], params: &TrainParams) -> Result<(McDanielModel, SolverReport)> {
    let Some(first) = sets.first() else {
        return Err(ClassifyError::TrainingSet { ground: 0, non_ground: 0 });
    };
    if let Some(other) = sets.iter().find(|s| s.feature_params != first.feature_params) {
        return Err(ClassifyError::invalid(
            "training sets",
            format!("{:?} and {:?}", first.feature_params, other.feature_params),
            "the same feature parameters in every set",
        ));
    }
    let n: usize = sets.iter().map(CandidateSet::len).sum();
    let rows = sets.iter().flat_map(|s| s.features.iter());
    let y: Vec<bool> = sets.iter().flat_map(|s| s.ground.iter().copied()).collect();
    let positives = y.iter().filter(|&&b| b).count();
    if positives == 0 || positives == n {
        return Err(ClassifyError::TrainingSet { ground: positives, non_ground: n - positives });
    }
    let mut mean = [0.0f64; FEATURE_COUNT];
    for f in rows.clone() {
        for k in 0..FEATURE_COUNT {
            mean[k] += f64::from(f[k]);
        }
    }
    mean.iter_mut().for_each(|m| *m /= n as f64);
    let mut var = [0.0f64; FEATURE_COUNT];
    for f in rows.clone() {
        for k in 0..FEATURE_COUNT {
            var[k] += (f64::from(f[k]) - mean[k]).powi(2);
        }
    }
    let std: Vec<f64> = var
        .iter()
        .map(|v| {
            let s = (v / n as f64).sqrt();
            if s > 1e-12 && s.is_finite() { s } else { 1.0 }
        })
        .collect();
    let mut x = Vec::with_capacity(n * FEATURE_COUNT);
    for f in rows {
        for k in 0..FEATURE_COUNT {
            x.push((f64::from(f[k]) - mean[k]) / std[k]);
        }
    }
    let svm = train_linear_svm(&x, FEATURE_COUNT, &y, &params.svm)?;
    let model = McDanielModel {
        format: MODEL_FORMAT.into(),
        version: MODEL_VERSION,
        features: FEATURE_NAMES.iter().map(|s| s.to_string()).collect(),
        feature_params: first.feature_params.clone(),
        mean: mean.to_vec(),
        std,
        weights: svm.weights.clone(),
        bias: svm.bias,
        c: params.svm.c,
        trained_on: params.trained_on.clone(),
    };
    model.check("<trained>").map_err(ClassifyError::Model)?;
    Ok((model, SolverReport { iterations: svm.iterations, converged: svm.converged, candidates: n, ground: positives }))
}

/// How training went.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct SolverReport {
    /// Outer iterations (passes) of the dual coordinate descent.
    pub iterations: usize,
    /// Whether the stopping tolerance was reached.
    pub converged: bool,
    /// Training candidates.
    pub candidates: usize,
    /// Of which ground.
    pub ground: usize,
}

/// Classification parameters besides the model.
#[derive(Clone, Debug, PartialEq)]
pub struct McDanielParams {
    /// A return is ground iff its column's candidate is ground and it lies at most this far above
    /// the candidate, metres (0 ..= 10; default 0.15: a column 0.5 m wide on a 17 deg slope rises
    /// 0.15 m, and lower bush parts stay out; on the forests h = 0.25 m let in twice the false
    /// positives of 0.15 m at the same recall, see the README).
    pub ground_height_m: f32,
    /// Candidates with a decision value above this are ground (finite; default 0, the SVM's own
    /// boundary; raise it for fewer false positives, as along the ROC curve).
    pub decision_threshold: f64,
    /// Known sensor origins by sensor id (vehicle frame), e.g. from a manifest; `None` estimates
    /// them per frame.
    pub sensor_origins: Option<Vec<Vec3>>,
}

impl Default for McDanielParams {
    fn default() -> Self {
        Self { ground_height_m: 0.15, decision_threshold: 0.0, sensor_origins: None }
    }
}

impl McDanielParams {
    /// Checks every field, naming it and its allowed range.
    pub fn validate(&self) -> Result<()> {
        if !(self.ground_height_m.is_finite() && (0.0..=10.0).contains(&self.ground_height_m)) {
            return Err(ClassifyError::invalid("ground_height_m", self.ground_height_m, "0 ..= 10"));
        }
        if !self.decision_threshold.is_finite() {
            return Err(ClassifyError::invalid("decision_threshold", self.decision_threshold, "finite"));
        }
        if let Some(o) = &self.sensor_origins
            && let Some(bad) = o.iter().find(|o| !o.is_finite())
        {
            return Err(ClassifyError::invalid("sensor_origins", bad, "finite coordinates, metres"));
        }
        Ok(())
    }
}

/// The bundled default model (see [`DEFAULT_MODEL_JSON`]).
pub fn default_model() -> Result<McDanielModel> {
    McDanielModel::from_json_str(DEFAULT_MODEL_JSON, "<built-in mcdaniel-forest.json>").map_err(ClassifyError::Model)
}

/// The classifier: a model, its parameters and the stage times of the last frame.
#[derive(Clone, Debug)]
pub struct McDaniel {
    /// The trained model.
    pub model: McDanielModel,
    /// Parameters.
    pub params: McDanielParams,
    /// Stage times of the last frame.
    pub times: McDanielTimes,
    /// Candidates of the last frame classified ground (diagnostics), in candidate order.
    pub candidate_ground: Vec<bool>,
}

impl McDaniel {
    /// A classifier with `model` and `params` (both checked).
    pub fn new(model: McDanielModel, params: McDanielParams) -> Result<Self> {
        params.validate()?;
        model.check("<model>").map_err(ClassifyError::Model)?;
        Ok(Self { model, params, times: McDanielTimes::default(), candidate_ground: Vec::new() })
    }

    /// Classifies every cell of `cloud` (all planes, grid order; see the module docs).
    pub fn classify(&mut self, cloud: &sim::OrderedCloud) -> Result<Vec<bool>> {
        let mut times = McDanielTimes::default();
        let (columns, features) =
            extract_features(cloud, &self.model.feature_params, self.params.sensor_origins.as_deref(), &mut times)?;
        let t = Instant::now();
        let threshold = self.params.decision_threshold;
        self.candidate_ground = features.iter().map(|f| self.model.decision_value(f) > threshold).collect();
        times.svm_s = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let h = self.params.ground_height_m;
        let decisions = (0..cloud.len())
            .map(|c| {
                let g = columns.column_of_cell[c];
                if g == columns::NONE {
                    return false;
                }
                let k = columns.candidate_of_column[g as usize] as usize;
                self.candidate_ground[k] && cloud.point_in_vehicle[c].z - columns.point_in_vehicle[k].z <= h
            })
            .collect();
        times.propagate_s = t.elapsed().as_secs_f64();
        self.times = times;
        Ok(decisions)
    }
}
