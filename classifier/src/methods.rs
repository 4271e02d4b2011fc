//! The registry of classification methods by name, behind one trait.

use glam::Affine3A;

use crate::baselines::grid::{GridAccumulation, GridParams};
use crate::baselines::ransac::{self, RansacParams};
use crate::error::{ClassifyError, Result};
use crate::learned::{Learned, LearnedModel};
use crate::mcdaniel::{McDaniel, McDanielModel, McDanielParams};
use crate::nitsch::{Nitsch, NitschParams, StageTimes};

/// Every method name, as the command line takes them.
pub const METHODS: &[&str] = &[
    "nitsch",
    "nitsch-0.7",
    "nitsch-no-cluster",
    "nitsch-no-cluster-0.7",
    "ransac",
    "grid",
    "grid-no-cluster",
    "grid-dror",
    "mcdaniel",
    "learned",
];

/// One frame to classify.
#[derive(Clone, Copy, Debug)]
pub struct FrameInput<'a> {
    /// Frame index (seeds RANSAC).
    pub index: usize,
    /// The cloud.
    pub cloud: &'a sim::OrderedCloud,
    /// Vehicle pose in the world (grid accumulation); `None` when unknown.
    pub world_from_vehicle: Option<Affine3A>,
}

/// A ground classifier: one decision per cell of the cloud (all planes, grid order), true = ground,
/// false for cells without a return. Methods may keep state between frames (grid accumulation), so
/// frames are given in order.
pub trait GroundClassifier {
    /// The method's registry name.
    fn name(&self) -> &'static str;
    /// Classifies one frame.
    fn classify(&mut self, frame: &FrameInput<'_>) -> Result<Vec<bool>>;
    /// Stage times of the last frame, where the method measures them.
    fn stage_times(&self) -> Option<StageTimes> {
        None
    }
    /// Stage times of the last frame as `(stage, seconds)` pairs in pipeline order, for any method
    /// that measures them (Nitsch: `features`, `clustering`; McDaniel: `origins`, `stage1`, `f1-f6`,
    /// `f7`, `f8`, `svm`, `propagate`); empty where none are measured.
    fn named_stage_times(&self) -> Vec<(&'static str, f64)> {
        self.stage_times().map_or_else(Vec::new, |t| vec![("features", t.features_s), ("clustering", t.clustering_s)])
    }
}

struct NitschMethod(&'static str, Nitsch);

impl GroundClassifier for NitschMethod {
    fn name(&self) -> &'static str {
        self.0
    }
    fn classify(&mut self, frame: &FrameInput<'_>) -> Result<Vec<bool>> {
        self.1.classify(frame.cloud)
    }
    fn stage_times(&self) -> Option<StageTimes> {
        Some(self.1.times)
    }
}

struct RansacMethod(RansacParams);

impl GroundClassifier for RansacMethod {
    fn name(&self) -> &'static str {
        "ransac"
    }
    fn classify(&mut self, frame: &FrameInput<'_>) -> Result<Vec<bool>> {
        ransac::classify(frame.cloud, &self.0, frame.index as u64)
    }
}

struct GridMethod(&'static str, GridAccumulation);

impl GroundClassifier for GridMethod {
    fn name(&self) -> &'static str {
        self.0
    }
    fn classify(&mut self, frame: &FrameInput<'_>) -> Result<Vec<bool>> {
        self.1.classify(frame.cloud, frame.world_from_vehicle)
    }
}

struct McDanielMethod(McDaniel);

impl GroundClassifier for McDanielMethod {
    fn name(&self) -> &'static str {
        "mcdaniel"
    }
    fn classify(&mut self, frame: &FrameInput<'_>) -> Result<Vec<bool>> {
        self.0.classify(frame.cloud)
    }
    fn named_stage_times(&self) -> Vec<(&'static str, f64)> {
        self.0.times.named()
    }
}

struct LearnedMethod(Learned);

impl GroundClassifier for LearnedMethod {
    fn name(&self) -> &'static str {
        "learned"
    }
    fn classify(&mut self, frame: &FrameInput<'_>) -> Result<Vec<bool>> {
        self.0.classify(frame.cloud)
    }
    fn named_stage_times(&self) -> Vec<(&'static str, f64)> {
        vec![("nitsch_and_features", self.0.times.nitsch_and_features_s), ("trees", self.0.times.trees_s)]
    }
}

/// The `learned` method with a given model (e.g. loaded from `--model FILE` with
/// [`LearnedModel::load`]).
pub fn learned_with_model(model: LearnedModel) -> Result<Box<dyn GroundClassifier + Send>> {
    Ok(Box::new(LearnedMethod(Learned::new(model)?)))
}

/// The `mcdaniel` method with a given model (e.g. loaded from `--model FILE` with
/// [`McDanielModel::load`]) and parameters.
pub fn mcdaniel_with_model(model: McDanielModel, params: McDanielParams) -> Result<Box<dyn GroundClassifier + Send>> {
    Ok(Box::new(McDanielMethod(McDaniel::new(model, params)?)))
}

/// Builds the method called `name` with its default parameters; `seed` seeds RANSAC. `mcdaniel`
/// uses the bundled model trained on the forests ([`crate::mcdaniel::default_model`]), `learned`
/// the bundled model trained on our scans ([`crate::learned::default_model`]).
pub fn method_by_name(name: &str, seed: u64) -> Result<Box<dyn GroundClassifier + Send>> {
    let nitsch = |threshold: f32, cluster: bool| NitschParams { threshold, cluster, ..Default::default() };
    Ok(match name {
        "nitsch" => Box::new(NitschMethod("nitsch", Nitsch::new(nitsch(0.6, true))?)),
        "nitsch-0.7" => Box::new(NitschMethod("nitsch-0.7", Nitsch::new(nitsch(0.7, true))?)),
        "nitsch-no-cluster" => Box::new(NitschMethod("nitsch-no-cluster", Nitsch::new(nitsch(0.6, false))?)),
        "nitsch-no-cluster-0.7" => Box::new(NitschMethod("nitsch-no-cluster-0.7", Nitsch::new(nitsch(0.7, false))?)),
        "ransac" => Box::new(RansacMethod(RansacParams { seed, ..Default::default() })),
        "grid" => Box::new(GridMethod("grid", GridAccumulation::new(GridParams::default())?)),
        "grid-no-cluster" => Box::new(GridMethod(
            "grid-no-cluster",
            GridAccumulation::new(GridParams { cluster: false, ..Default::default() })?,
        )),
        "grid-dror" => Box::new(GridMethod(
            "grid-dror",
            GridAccumulation::new(GridParams { isolation: Some(Default::default()), ..Default::default() })?,
        )),
        "mcdaniel" => mcdaniel_with_model(crate::mcdaniel::default_model()?, McDanielParams::default())?,
        "learned" => learned_with_model(crate::learned::default_model()?)?,
        _ => return Err(ClassifyError::UnknownMethod { name: name.to_string(), known: METHODS.join(", ") }),
    })
}
