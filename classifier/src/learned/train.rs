//! Training the learned method: labelled frames of our own scans in, a [`LearnedModel`] out. The
//! training set is always built; growing the trees needs the cargo feature `train` (hessboost:
//! minutes of build that a user who only classifies should not wait for), and [`train`] says so
//! without it.
//!
//! The trees come from **hessboost** (a maintained, pure-Rust gradient-boosting library with
//! XGBoost's parameters): `binary:logistic`, `tree_method = hist`, `grow_policy = symmetric`
//! (oblivious trees, CatBoost-style: one split per level), which is what makes inference cheap
//! ([`super::forest`]), and training that gives the same model on any thread count. Chosen over a
//! network: a Rust framework (burn, candle) brings hundreds of crates and minutes of build to every
//! user of the classifier, and the features are tabular; over LightGBM or XGBoost bindings: a C++
//! build, and trees whose evaluation branches on every node.
//!
//! From each frame, at most [`TrainParams::samples_per_frame`] returns of plane 0 are drawn
//! (seeded by the frame's key, so the set does not depend on the order frames arrive in once they
//! are sorted by key); the frames of every [`TrainParams::validation_every`]-th sequence are held
//! out instead (whole sequences, so that no held-out frame has a trained twin), to choose the
//! decision threshold (the ground probability that maximises F1 on them) and to report scores.
//! Deterministic for a seed.

#[cfg(feature = "train")]
use hessboost::prelude::{DMatrix, HessboostError, Objective, TrainingParams, TreeMethod, train as train_booster};
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use serde::Serialize;

use super::features::FEATURE_COUNT;
use super::model::{LearnedModel, ObliviousTree};
use super::{Extractor, Forest, LANES};
use crate::error::{ClassifyError, Result};
use crate::metrics::Confusion;

/// Training parameters.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TrainParams {
    /// Boosting rounds (trees), 1 ..= 5000.
    pub trees: usize,
    /// Tree depth, 1 ..= 10.
    pub depth: usize,
    /// Learning rate, 0 < eta <= 1.
    pub eta: f64,
    /// L2 regularisation of the leaves.
    pub lambda: f64,
    /// Smallest hessian sum of a child.
    pub min_child_weight: f64,
    /// Histogram bins per feature, 2 ..= 256.
    pub max_bin: usize,
    /// Returns drawn from each training frame, 1 ..= 10 million.
    pub samples_per_frame: usize,
    /// Every this many sequences one is held out for validation (0: none; then the threshold is 0.5).
    pub validation_every: usize,
    /// Seed of the sampling and of the library.
    pub seed: u64,
    /// Worker threads (`None`: all cores). The model is the same at any count (so the model file
    /// does not record it).
    #[serde(skip)]
    pub threads: Option<usize>,
}

impl Default for TrainParams {
    fn default() -> Self {
        Self {
            trees: 300,
            depth: 6,
            eta: 0.1,
            lambda: 1.0,
            min_child_weight: 1.0,
            max_bin: 256,
            samples_per_frame: 20_000,
            validation_every: 8,
            seed: 0,
            threads: None,
        }
    }
}

impl TrainParams {
    /// Refuses values outside their ranges.
    pub fn validate(&self) -> Result<()> {
        if !(1..=5000).contains(&self.trees) {
            return Err(ClassifyError::invalid("trees", self.trees, "1 ..= 5000"));
        }
        if !(1..=super::model::MAX_DEPTH).contains(&self.depth) {
            return Err(ClassifyError::invalid("depth", self.depth, "1 ..= 10"));
        }
        if !(self.eta.is_finite() && self.eta > 0.0 && self.eta <= 1.0) {
            return Err(ClassifyError::invalid("eta", self.eta, "0 < eta <= 1"));
        }
        if !(self.lambda.is_finite() && self.lambda >= 0.0) {
            return Err(ClassifyError::invalid("lambda", self.lambda, ">= 0"));
        }
        if !(self.min_child_weight.is_finite() && self.min_child_weight >= 0.0) {
            return Err(ClassifyError::invalid("min_child_weight", self.min_child_weight, ">= 0"));
        }
        if !(2..=256).contains(&self.max_bin) {
            return Err(ClassifyError::invalid("max_bin", self.max_bin, "2 ..= 256"));
        }
        if !(1..=10_000_000).contains(&self.samples_per_frame) {
            return Err(ClassifyError::invalid("samples_per_frame", self.samples_per_frame, "1 ..= 10000000"));
        }
        if self.threads == Some(0) {
            return Err(ClassifyError::invalid("threads", 0, ">= 1"));
        }
        Ok(())
    }
}

/// Features and labels drawn from labelled frames.
#[derive(Clone, Debug, Default)]
pub struct TrainingSet {
    /// Training rows, row-major (`FEATURE_COUNT` per row).
    pub rows: Vec<f32>,
    /// Their labels (1 ground, 0 not).
    pub labels: Vec<f32>,
    /// Held-out rows (every return of the held-out frames), feature-major per frame.
    pub valid_rows: Vec<f32>,
    /// Their labels.
    pub valid_labels: Vec<f32>,
    /// Frames drawn from, and held out.
    pub frames: (usize, usize),
}

impl TrainingSet {
    /// Training rows.
    pub fn len(&self) -> usize {
        self.labels.len()
    }

    /// Whether there are no training rows.
    pub fn is_empty(&self) -> bool {
        self.labels.is_empty()
    }

    /// Appends another set's rows (frames counted), after this one's.
    pub fn append(&mut self, other: TrainingSet) {
        self.rows.extend(other.rows);
        self.labels.extend(other.labels);
        self.valid_rows.extend(other.valid_rows);
        self.valid_labels.extend(other.valid_labels);
        self.frames.0 += other.frames.0;
        self.frames.1 += other.frames.1;
    }

    /// Adds frame number `ordinal` (in a fixed order of the frames) of `cloud`, whose `ground`
    /// field is the truth: its features are computed with `extractor`; a held-out frame gives every
    /// return, a training frame a sample seeded by `params.seed` and `ordinal`.
    pub fn add_frame(
        &mut self,
        extractor: &mut Extractor,
        cloud: &sim::OrderedCloud,
        ordinal: u64,
        held_out: bool,
        params: &TrainParams,
    ) -> Result<()> {
        let mut out = vec![false; cloud.len()];
        extractor.compute(cloud, &mut out)?;
        let features = &extractor.features;
        let cols = &features.columns;
        // Returns by their index among the features (`features.cells[j]` is the grid cell).
        let cells: Vec<usize> = (0..features.len()).collect();
        let truth = |j: usize| f32::from(u8::from(cloud.ground[features.cells[j] as usize]));
        if held_out {
            self.frames.1 += 1;
            for &j in &cells {
                self.valid_rows.extend((0..FEATURE_COUNT).map(|k| cols[k][j]));
                self.valid_labels.push(truth(j));
            }
            return Ok(());
        }
        self.frames.0 += 1;
        // A seeded partial shuffle: the first `take` of a Fisher-Yates pass.
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(params.seed ^ ordinal.wrapping_mul(0x9e37_79b9_7f4a_7c15));
        let mut order = cells;
        let take = params.samples_per_frame.min(order.len());
        for k in 0..take {
            let j = rng.random_range(k..order.len());
            order.swap(k, j);
        }
        order.truncate(take);
        order.sort_unstable();
        for &j in &order {
            self.rows.extend((0..FEATURE_COUNT).map(|k| cols[k][j]));
            self.labels.push(truth(j));
        }
        Ok(())
    }
}

/// What training reports.
#[derive(Clone, Debug, Serialize)]
pub struct TrainReport {
    /// Training rows and their ground share.
    pub rows: usize,
    /// Share of ground among the training rows.
    pub ground_share: f64,
    /// Frames trained on and held out.
    pub frames: (usize, usize),
    /// Held-out returns.
    pub valid_rows: usize,
    /// F1, precision and recall on the held-out returns at the chosen threshold.
    pub valid_f1: f64,
    /// Precision on the held-out returns.
    pub valid_precision: f64,
    /// Recall on the held-out returns.
    pub valid_recall: f64,
    /// F1 of Nitsch's decisions on the held-out returns (feature `nitsch`), for comparison.
    pub valid_f1_nitsch: f64,
    /// The chosen threshold.
    pub threshold: f32,
    /// Seconds in the library.
    pub seconds: f64,
}

/// What [`train`] says in a build without the cargo feature `train`.
pub const NOT_BUILT: &str = "this build cannot train (no cargo feature `train`): build with `--features train` (`cargo install --path . --features full`)";

/// Whether this build can train (the cargo feature `train`).
pub const BUILT: bool = cfg!(feature = "train");

/// Converts one of hessboost's trees (grown with `grow_policy = symmetric`) into an
/// [`ObliviousTree`]; its leaves scaled by `weight`. Refused if the tree is not symmetric.
#[cfg(feature = "train")]
pub fn oblivious_from(tree: &hessboost::tree::RegTree, weight: f32) -> Result<ObliviousTree> {
    let nodes = tree.nodes();
    let depth = tree.depth();
    let not_symmetric = |why: String| ClassifyError::Training(format!("a tree is not symmetric: {why}"));
    if depth == 0 {
        // A single leaf: a depth-1 tree whose two leaves agree.
        let v = nodes.first().map_or(0.0, |n| n.leaf_value) * weight;
        return Ok(ObliviousTree { features: vec![0], thresholds: vec![0.0], leaves: vec![v, v] });
    }
    let mut levels: Vec<Option<(u32, f32)>> = vec![None; depth];
    let mut leaves = vec![f32::NAN; 1 << depth];
    // (node, level, path bits so far)
    let mut stack = vec![(0usize, 0usize, 0usize)];
    while let Some((id, level, bits)) = stack.pop() {
        let node = &nodes[id];
        if node.is_leaf() {
            let span = 1usize << (depth - level);
            leaves[bits * span..(bits + 1) * span].fill(node.leaf_value * weight);
            continue;
        }
        if node.is_categorical {
            return Err(not_symmetric("a categorical split".to_string()));
        }
        let split = (node.split_feature, node.split_cond);
        match levels[level] {
            None => levels[level] = Some(split),
            Some(s) if s == split => {}
            Some(s) => return Err(not_symmetric(format!("level {level} splits on {s:?} and {split:?}"))),
        }
        // XGBoost's convention: `x < split_cond` goes left (bit 0), else right (bit 1).
        stack.push((node.left as usize, level + 1, 2 * bits));
        stack.push((node.right as usize, level + 1, 2 * bits + 1));
    }
    let mut features = Vec::with_capacity(depth);
    let mut thresholds = Vec::with_capacity(depth);
    for (l, s) in levels.iter().enumerate() {
        let (f, t) = s.ok_or_else(|| not_symmetric(format!("level {l} has no split")))?;
        features.push(u8::try_from(f).map_err(|_| not_symmetric(format!("feature {f}")))?);
        thresholds.push(t);
    }
    if leaves.iter().any(|v| !v.is_finite()) {
        return Err(not_symmetric("a leaf slot is unfilled".to_string()));
    }
    Ok(ObliviousTree { features, thresholds, leaves })
}

#[cfg(feature = "train")]
fn library_error(e: HessboostError) -> ClassifyError {
    ClassifyError::Training(format!("hessboost: {e}"))
}

/// The trees grown on `set` (hessboost) and their base score.
#[cfg(feature = "train")]
fn boost(set: &TrainingSet, params: &TrainParams) -> Result<(f32, Vec<ObliviousTree>)> {
    let dtrain = DMatrix::from_dense(&set.rows, set.len(), FEATURE_COUNT)
        .and_then(|m| m.with_labels(&set.labels))
        .map_err(library_error)?;
    let mut builder = TrainingParams::builder()
        .objective(Objective::BinaryLogistic(hessboost::objective::RegLoss::default()))
        .tree_method(TreeMethod::Hist)
        .grow_policy(hessboost::config::GrowPolicy::Symmetric)
        .max_depth(params.depth)
        .eta(params.eta)
        .lambda(params.lambda)
        .min_child_weight(params.min_child_weight)
        .max_bin(params.max_bin)
        .seed(params.seed);
    if let Some(t) = params.threads {
        builder = builder.nthread(t);
    }
    let hparams = builder.build().map_err(library_error)?;
    let booster = train_booster(&hparams, &dtrain, params.trees).map_err(library_error)?;
    let trees: Vec<ObliviousTree> =
        booster.trees().iter().zip(booster.tree_weights()).map(|(t, w)| oblivious_from(t, w)).collect::<Result<_>>()?;
    Ok((booster.base_score(), trees))
}

/// Without the cargo feature `train`: refused ([`NOT_BUILT`]).
#[cfg(not(feature = "train"))]
fn boost(_set: &TrainingSet, _params: &TrainParams) -> Result<(f32, Vec<ObliviousTree>)> {
    Err(ClassifyError::Training(NOT_BUILT.to_string()))
}

/// Trains a model on `set`; `trained_on` describes the data for the model file.
pub fn train(
    set: &TrainingSet,
    params: &TrainParams,
    trained_on: serde_json::Value,
) -> Result<(LearnedModel, TrainReport)> {
    params.validate()?;
    let ground = set.labels.iter().filter(|&&y| y > 0.5).count();
    if ground == 0 || ground == set.len() {
        return Err(ClassifyError::TrainingSet { ground, non_ground: set.len() - ground });
    }
    let t0 = std::time::Instant::now();
    let (base_score, trees) = boost(set, params)?;
    let seconds = t0.elapsed().as_secs_f64();
    let mut model = LearnedModel::new(base_score, 0.5, trees);
    // The threshold: the best F1 on the held-out frames, over probabilities 0.05 .. 0.95.
    let (mut report_f1, mut report_p, mut report_r, mut nitsch_f1) = (f64::NAN, f64::NAN, f64::NAN, f64::NAN);
    if !set.valid_labels.is_empty() {
        let count = set.valid_labels.len();
        let padded = count.div_ceil(LANES) * LANES;
        let columns: Vec<Vec<f32>> = (0..FEATURE_COUNT)
            .map(|k| {
                let mut c: Vec<f32> = set.valid_rows.chunks_exact(FEATURE_COUNT).map(|r| r[k]).collect();
                c.resize(padded, 0.0);
                c
            })
            .collect();
        let mut margins = vec![0.0; count];
        Forest::new(&model).margins(&columns, count, &mut margins);
        let score = |cut: f32| {
            let mut c = Confusion::default();
            for (&m, &y) in margins.iter().zip(&set.valid_labels) {
                c.add(y > 0.5, m > cut);
            }
            c
        };
        let mut best = (f64::NEG_INFINITY, 0.5f32);
        for k in 1..20 {
            let p = k as f32 * 0.05;
            let f1 = score((p / (1.0 - p)).ln()).f1();
            if f1 > best.0 {
                best = (f1, p);
            }
        }
        model.threshold = best.1;
        let c = score(model.margin_threshold());
        (report_f1, report_p, report_r) = (c.f1(), c.precision(), c.recall());
        let mut n = Confusion::default();
        let nitsch_index = super::FEATURE_NAMES.iter().position(|&f| f == "nitsch").expect("a feature");
        for (row, &y) in set.valid_rows.chunks_exact(FEATURE_COUNT).zip(&set.valid_labels) {
            n.add(y > 0.5, row[nitsch_index] > 0.5);
        }
        nitsch_f1 = n.f1();
    }
    model.trained_on = trained_on;
    model.training = serde_json::json!({
        "library": "hessboost 0.4 (binary:logistic, hist, grow_policy symmetric)",
        "params": params,
        "rows": set.len(),
        "frames": set.frames,
    });
    model.check("<trained>").map_err(ClassifyError::LearnedModel)?;
    let report = TrainReport {
        rows: set.len(),
        ground_share: ground as f64 / set.len() as f64,
        frames: set.frames,
        valid_rows: set.valid_labels.len(),
        valid_f1: report_f1,
        valid_precision: report_p,
        valid_recall: report_r,
        valid_f1_nitsch: nitsch_f1,
        threshold: model.threshold,
        seconds,
    };
    Ok((model, report))
}

#[cfg(all(test, feature = "train"))]
mod tests {
    use super::*;
    use hessboost::prelude::Iterations;

    /// A small labelled set: ground is `x0 < 0.3 && x6 < 0.2` (the "nitsch" feature and a height).
    fn set(n: usize, seed: u64) -> TrainingSet {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        let mut s = TrainingSet::default();
        for _ in 0..n {
            let row: [f32; FEATURE_COUNT] = std::array::from_fn(|_| rng.random::<f32>());
            s.labels.push(f32::from(u8::from(row[0] < 0.3 && row[6] < 0.2)));
            s.rows.extend(row);
        }
        s
    }

    #[test]
    fn the_exported_trees_give_the_librarys_margins_and_training_is_deterministic() {
        let data = set(4000, 1);
        let params =
            TrainParams { trees: 20, depth: 4, validation_every: 0, threads: Some(1), ..TrainParams::default() };
        let (a, _) = train(&data, &params, serde_json::Value::Null).unwrap();
        let (b, _) =
            train(&data, &TrainParams { threads: Some(2), ..params.clone() }, serde_json::Value::Null).unwrap();
        assert_eq!(a.trees, b.trees, "the same model on 1 and 2 threads");
        // Every tree is oblivious with depth 4 or less, and our margins are the library's.
        let dm = DMatrix::from_dense(&data.rows, data.len(), FEATURE_COUNT).unwrap();
        let hparams = TrainingParams::builder()
            .objective(Objective::BinaryLogistic(hessboost::objective::RegLoss::default()))
            .tree_method(TreeMethod::Hist)
            .grow_policy(hessboost::config::GrowPolicy::Symmetric)
            .max_depth(4)
            .eta(params.eta)
            .nthread(1)
            .build()
            .unwrap();
        let booster = train_booster(&hparams, &dm.clone().with_labels(&data.labels).unwrap(), 20).unwrap();
        let theirs = booster.predict_margin(&dm, Iterations::Best).unwrap();
        let mut worst = 0.0f32;
        for (k, row) in data.rows.chunks_exact(FEATURE_COUNT).enumerate() {
            let x: [f32; FEATURE_COUNT] = row.try_into().unwrap();
            worst = worst.max((a.margin(&x) - theirs.as_slice()[k]).abs());
        }
        assert!(worst < 1e-4, "largest margin difference {worst}");
        // The rule is learnt.
        let test = set(2000, 2);
        let mut c = Confusion::default();
        for (row, &y) in test.rows.chunks_exact(FEATURE_COUNT).zip(&test.labels) {
            let x: [f32; FEATURE_COUNT] = row.try_into().unwrap();
            c.add(y > 0.5, a.margin(&x) > 0.0);
        }
        assert!(c.f1() > 0.95, "F1 {}", c.f1());
    }

    #[test]
    fn bad_parameters_and_one_class_sets_are_refused() {
        let data = set(100, 1);
        for (p, field) in [
            (TrainParams { trees: 0, ..TrainParams::default() }, "trees"),
            (TrainParams { depth: 11, ..TrainParams::default() }, "depth"),
            (TrainParams { eta: f64::NAN, ..TrainParams::default() }, "eta"),
            (TrainParams { threads: Some(0), ..TrainParams::default() }, "threads"),
        ] {
            let e = train(&data, &p, serde_json::Value::Null).unwrap_err().to_string();
            assert!(e.contains(field), "{e}");
        }
        let mut one = data.clone();
        one.labels.fill(0.0);
        let e = train(&one, &TrainParams::default(), serde_json::Value::Null).unwrap_err().to_string();
        assert!(e.contains("both classes"), "{e}");
    }
}
