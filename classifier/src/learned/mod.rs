//! The learned method: gradient-boosted oblivious trees, trained only on scans this project
//! generates, on top of Nitsch et al.
//!
//! Per frame: Nitsch's method runs first ([`crate::nitsch`]); its normals, qualities, decisions and
//! clusters, the ordered grid and a ground height map built from its decisions give every return
//! of echo plane 0 fifteen features that do not depend on the frame's origin or heading
//! ([`features`]); the model ([`model`], evaluated by [`forest`]) gives each a ground probability,
//! ground where it is above the model's threshold. Returns of further echo planes take the
//! decision of the nearest plane-0 return, as in Nitsch's method. The model learns where Nitsch's
//! rules go wrong on our ground truth: curb faces and kerbs (labelled sidewalk), ground beside
//! objects, low vegetation and raised flat tops.
//!
//! Training ([`train`], cargo feature `train`) uses hessboost's symmetric (oblivious) trees: a tree
//! asks one question per level, so a model of hundreds of trees classifies a 124 k-point frame in
//! a few milliseconds; no Python at inference. The bundled model
//! ([`default_model`], `classifier/models/learned-default.json`) is made by
//! `groundtruth train --method learned --config examples/train-learned.toml`.

pub mod features;
pub mod forest;
pub mod ground_map;
pub mod model;
pub mod train;

use std::time::Instant;

pub use features::{FEATURE_COUNT, FEATURE_NAMES, FeatureColumns};
pub use forest::{Forest, LANES};
pub use model::{LearnedModel, LearnedModelError, ObliviousTree};

use crate::error::{ClassifyError, Result, check_cloud_and_output};
use crate::nitsch::{Nitsch, NitschParams, echoes_from_plane0};

/// The bundled model's JSON.
pub const DEFAULT_MODEL_JSON: &str = include_str!("../../models/learned-default.json");

/// The bundled model, trained on our scans of every scene family with the roof rigs
/// (`examples/train-learned.toml`).
pub fn default_model() -> Result<LearnedModel> {
    LearnedModel::from_json_str(DEFAULT_MODEL_JSON, "<built-in learned-default.json>")
        .map_err(ClassifyError::LearnedModel)
}

/// The parameters of Nitsch's method as the learned method runs it: the defaults, without the row
/// reordering of nodding lasers (the method is trained on spinning sensors).
pub fn nitsch_params() -> NitschParams {
    NitschParams { fix_row_order: false, ..NitschParams::default() }
}

/// Time spent in the stages of the last frame, seconds.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LearnedTimes {
    /// Nitsch's method and the features.
    pub nitsch_and_features_s: f64,
    /// The trees and the decisions.
    pub trees_s: f64,
}

/// Nitsch's method and the features of its result: what the trees are trained and run on.
#[derive(Clone, Debug)]
pub struct Extractor {
    nitsch: Nitsch,
    /// The features of the last frame.
    pub features: FeatureColumns,
    /// Nitsch's plane-0 decisions of the last frame.
    pub nitsch_ground: Vec<bool>,
}

impl Extractor {
    /// An extractor with Nitsch's parameters of [`nitsch_params`].
    pub fn new() -> Result<Self> {
        Ok(Self {
            nitsch: Nitsch::new(nitsch_params())?,
            features: FeatureColumns::default(),
            nitsch_ground: Vec::new(),
        })
    }

    /// Runs Nitsch's method on `cloud`, writing its decisions to `out` (every cell, all planes),
    /// and computes the features of plane 0 ([`Extractor::features`]).
    pub fn compute(&mut self, cloud: &sim::OrderedCloud, out: &mut [bool]) -> Result<()> {
        check_cloud_and_output(cloud, out)?;
        self.nitsch.classify_into(cloud, out)?;
        let n = cloud.rows * cloud.cols;
        self.nitsch_ground.clear();
        self.nitsch_ground.extend_from_slice(&out[..n]);
        self.features.compute(cloud, &self.nitsch, &self.nitsch_ground);
        Ok(())
    }

    /// Largest distance at which an echo of a further plane takes a plane-0 decision, metres.
    pub fn echo_match_m(&self) -> f32 {
        self.nitsch.params.echo_match_m
    }
}

/// The classifier with its model and reusable buffers.
#[derive(Clone, Debug)]
pub struct Learned {
    /// The model.
    pub model: LearnedModel,
    forest: Forest,
    /// Nitsch's method and the features.
    pub extractor: Extractor,
    plane0: Vec<bool>,
    margins: Vec<f32>,
    /// Stage times of the last frame.
    pub times: LearnedTimes,
}

impl Learned {
    /// A classifier with `model` (checked).
    pub fn new(model: LearnedModel) -> Result<Self> {
        model.check("<model>").map_err(ClassifyError::LearnedModel)?;
        Ok(Self {
            forest: Forest::new(&model),
            model,
            extractor: Extractor::new()?,
            plane0: Vec::new(),
            margins: Vec::new(),
            times: LearnedTimes::default(),
        })
    }

    /// Classifies every cell of `cloud` (all planes, grid order): true = ground; cells without a
    /// return are false.
    pub fn classify(&mut self, cloud: &sim::OrderedCloud) -> Result<Vec<bool>> {
        let mut out = vec![false; cloud.len()];
        self.classify_into(cloud, &mut out)?;
        Ok(out)
    }

    /// As [`Learned::classify`], writing into `out` (length `cloud.len()`).
    pub fn classify_into(&mut self, cloud: &sim::OrderedCloud, out: &mut [bool]) -> Result<()> {
        let t0 = Instant::now();
        self.extractor.compute(cloud, out)?;
        let t1 = Instant::now();
        let n = cloud.rows * cloud.cols;
        let features = &self.extractor.features;
        let count = features.len();
        self.margins.resize(count, 0.0);
        self.forest.margins(&features.columns, count, &mut self.margins);
        let cut = self.model.margin_threshold();
        out[..n].fill(false);
        for (&i, &m) in self.extractor.features.cells.iter().zip(&self.margins) {
            out[i as usize] = m > cut;
        }
        self.plane0.clear();
        self.plane0.extend_from_slice(&out[..n]);
        echoes_from_plane0(cloud, &self.plane0, self.extractor.echo_match_m(), out);
        self.times =
            LearnedTimes { nitsch_and_features_s: (t1 - t0).as_secs_f64(), trees_s: t1.elapsed().as_secs_f64() };
        Ok(())
    }
}
