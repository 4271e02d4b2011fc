//! The method of Nitsch et al.: features on echo plane 0, ground candidates by a `g_rho`
//! threshold, conditional Euclidean clustering and the cluster rules (or, for the ablation, the
//! threshold alone).
//!
//! Echo planes > 0 (decision): second and third echoes are sparse on their own planes, so they get
//! no features of their own. Each takes the decision of the nearest plane-0 return among the 3 x 3
//! cells around it if that return is within `echo_match_m`, and is not ground otherwise (a second
//! echo from the ground behind a thin object lies next to plane-0 ground; one behind a bush does not).

pub mod cluster;
pub mod features;
pub mod neighbours;
pub mod row_order;
mod row_returns;

use glam::Vec3;

use crate::error::{ClassifyError, Result, check_cloud_and_output, is_valid};
use crate::nitsch::cluster::{ClusterParams, ClusterWorkspace, cluster_candidates_searched};
use crate::nitsch::features::{FeatureParams, Features, compute_features};
use crate::nitsch::neighbours::{GridView, NeighbourParams, Wrap, detect_wrap};

/// All parameters of the method.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NitschParams {
    /// Candidate threshold on `g_rho` (0.6 or 0.7 in the paper).
    pub threshold: f32,
    /// Whether to cluster (false: the paper's ablation, threshold only).
    pub cluster: bool,
    /// Neighbour lookup.
    pub neighbours: NeighbourParams,
    /// Feature computation.
    pub features: FeatureParams,
    /// Clustering and cluster rules.
    pub clustering: ClusterParams,
    /// Largest distance at which an echo of plane > 0 takes a plane-0 decision, metres.
    pub echo_match_m: f32,
    /// Flip the rows of columns that run down in elevation before the features
    /// ([`row_order`]: the rear flanks of a nodding laser); ordinary rigs are unaffected.
    pub fix_row_order: bool,
}

impl Default for NitschParams {
    fn default() -> Self {
        Self {
            threshold: 0.6,
            cluster: true,
            neighbours: NeighbourParams::default(),
            features: FeatureParams::default(),
            clustering: ClusterParams::default(),
            echo_match_m: 0.5,
            fix_row_order: true,
        }
    }
}

impl NitschParams {
    /// Refuses values outside their ranges.
    pub fn validate(&self) -> Result<()> {
        if !(self.threshold.is_finite() && (-1.0..=1.0).contains(&self.threshold)) {
            return Err(ClassifyError::invalid("threshold", self.threshold, "-1 ..= 1"));
        }
        if self.neighbours.max_col_gap == 0 || self.neighbours.max_col_gap > 64 {
            return Err(ClassifyError::invalid("max_col_gap", self.neighbours.max_col_gap, "1 ..= 64"));
        }
        if !(self.echo_match_m.is_finite() && self.echo_match_m >= 0.0) {
            return Err(ClassifyError::invalid("echo_match_m", self.echo_match_m, "finite, >= 0"));
        }
        self.features.validate()?;
        self.clustering.validate()
    }
}

/// Time spent in the stages of the last frame, seconds (for benchmarks).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StageTimes {
    /// Feature extraction.
    pub features_s: f64,
    /// Candidate selection, clustering and cluster rules.
    pub clustering_s: f64,
}

/// The classifier with its reusable buffers.
#[derive(Clone, Debug, Default)]
pub struct Nitsch {
    /// Parameters.
    pub params: NitschParams,
    /// Features of the last frame's plane 0 (in the reordered grid where [`row_order`] flipped columns).
    pub features: Features,
    /// Clusters of the last frame (diagnostics).
    pub workspace: ClusterWorkspace,
    candidate: Vec<bool>,
    plane0_ground: Vec<bool>,
    /// Plane 0 with reversed columns flipped ([`row_order`]), and its decisions.
    reordered: (Vec<Vec3>, Vec<f32>, Vec<bool>),
    /// Stage times of the last frame.
    pub times: StageTimes,
}

impl Nitsch {
    /// A classifier with `params` (validated).
    pub fn new(params: NitschParams) -> Result<Self> {
        params.validate()?;
        Ok(Self { params, ..Self::default() })
    }

    /// Resolves the wrap setting for plane 0 of `cloud`.
    pub fn view<'a>(&self, cloud: &'a sim::OrderedCloud) -> GridView<'a> {
        let n = cloud.rows * cloud.cols;
        let points = &cloud.point_in_vehicle[..n];
        let wrap = match self.params.neighbours.wrap {
            Wrap::Always => true,
            Wrap::Never => false,
            Wrap::Auto => detect_wrap(points, cloud.rows, cloud.cols),
        };
        GridView {
            points,
            ranges: &cloud.range_m[..n],
            rows: cloud.rows,
            cols: cloud.cols,
            wrap,
            max_col_gap: self.params.neighbours.max_col_gap,
        }
    }

    /// Classifies every cell of `cloud` (all planes, grid order): true = ground. Cells without a
    /// return are false.
    pub fn classify(&mut self, cloud: &sim::OrderedCloud) -> Result<Vec<bool>> {
        let mut out = vec![false; cloud.len()];
        self.classify_into(cloud, &mut out)?;
        Ok(out)
    }

    /// As [`Nitsch::classify`], writing into `out` (length `cloud.len()`).
    pub fn classify_into(&mut self, cloud: &sim::OrderedCloud, out: &mut [bool]) -> Result<()> {
        check_cloud_and_output(cloud, out)?;
        let t0 = std::time::Instant::now();
        let reversed = if self.params.fix_row_order { row_order::reversed_columns(cloud) } else { None };
        let n = cloud.rows * cloud.cols;
        self.plane0_ground.resize(n, false);
        let t1 = match &reversed {
            None => {
                let view = self.view(cloud);
                let mut ground = std::mem::take(&mut self.plane0_ground);
                let t1 = self.decide_plane0(&view, &mut ground);
                self.plane0_ground = ground;
                t1
            }
            Some(rev) => {
                let (mut points, mut ranges, mut ground) = std::mem::take(&mut self.reordered);
                row_order::reorder_plane0(cloud, rev, &mut points, &mut ranges);
                let mut view = self.view(cloud);
                view.points = &points;
                view.ranges = &ranges;
                ground.resize(n, false);
                let t1 = self.decide_plane0(&view, &mut ground);
                for r in 0..cloud.rows {
                    for c in 0..cloud.cols {
                        let src = row_order::source_cell(rev, cloud.rows, cloud.cols, r, c);
                        self.plane0_ground[src] = ground[r * cloud.cols + c];
                    }
                }
                self.reordered = (points, ranges, ground);
                t1
            }
        };
        self.times = StageTimes { features_s: (t1 - t0).as_secs_f64(), clustering_s: t1.elapsed().as_secs_f64() };
        out[..n].copy_from_slice(&self.plane0_ground);
        echoes_from_plane0(cloud, &self.plane0_ground, self.params.echo_match_m, out);
        Ok(())
    }
}

impl Nitsch {
    /// Features, candidates and (optionally) clustering on one plane-0 view, writing its decisions
    /// into `ground`; returns when the features were done (stage times).
    fn decide_plane0(&mut self, view: &GridView<'_>, ground: &mut [bool]) -> std::time::Instant {
        compute_features(view, &self.params.features, &mut self.features);
        let t1 = std::time::Instant::now();
        let thr = self.params.threshold;
        if self.params.cluster {
            self.candidate.clear();
            self.candidate.extend(self.features.g_rho.iter().map(|&g| g >= thr && g > 0.0));
            cluster_candidates_searched(
                view,
                self.features.valid(),
                self.features.search(),
                &self.candidate,
                &self.features.normal,
                &self.params.clustering,
                &mut self.workspace,
            );
            let returns = self.workspace.returns();
            self.workspace.decide(view.points, returns, &self.params.clustering, ground);
        } else {
            for (g, &q) in ground.iter_mut().zip(&self.features.g_rho) {
                *g = q >= thr && q > 0.0;
            }
        }
        t1
    }
}

/// Decides the cells of planes > 0 from the plane-0 decisions `plane0` (module docs).
pub fn echoes_from_plane0(cloud: &sim::OrderedCloud, plane0: &[bool], echo_match_m: f32, out: &mut [bool]) {
    let (rows, cols) = (cloud.rows, cloud.cols);
    let cells = rows * cols;
    let pts = &cloud.point_in_vehicle;
    for plane in 1..cloud.planes {
        let start = plane * cells;
        let (plane_pts, plane_out) = (&pts[start..start + cells], &mut out[start..start + cells]);
        plane_out.fill(false);
        // Later echoes are few: most cells of these planes are no-returns.
        for (k, &p) in plane_pts.iter().enumerate() {
            if !is_valid(p) {
                continue;
            }
            let (r, c) = (k / cols, k % cols);
            let mut best = (echo_match_m * echo_match_m, None::<usize>);
            for rr in r.saturating_sub(1)..=(r + 1).min(rows - 1) {
                for cc in c.saturating_sub(1)..=(c + 1).min(cols - 1) {
                    let j = rr * cols + cc;
                    let q: Vec3 = pts[j];
                    if is_valid(q) {
                        let d2 = p.distance_squared(q);
                        if d2 <= best.0 {
                            best = (d2, Some(j));
                        }
                    }
                }
            }
            plane_out[k] = best.1.is_some_and(|j| plane0[j]);
        }
    }
}
