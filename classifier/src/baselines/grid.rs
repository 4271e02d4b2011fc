//! Grid accumulation of the features over frames (the "grid accumulation of features" rows of
//! Table I): a multi-layer 2-D grid map in the world frame, in the spirit of the grid_map library.
//!
//! Layers per square of `cell_m` (decisions, the paper gives only the 15 cm rule):
//! - `g_rho` layer: the mean `g_rho` of every plane-0 return that fell into the square so far;
//! - elevation layer: the mean world height of the ground candidates (`g_rho >= threshold`) that
//!   fell into the square so far.
//!
//! A square is a ground patch when its mean `g_rho` reaches the threshold and it has an elevation.
//! A point is ground when its square is a ground patch and the point lies within `max_height_m`
//! (15 cm) of the patch's elevation. Frames are accumulated in the order they are classified, the
//! current frame included, using `world_from_vehicle`; without a pose the map is reset every frame
//! (the frame is its own map). With clustering, the points the grid calls ground are the candidates
//! of the clustering and cluster rules of [`crate::nitsch::cluster`] (plane 0; other planes as in
//! [`crate::nitsch`]); without, every return is tested against the map directly.
//!
//! With `isolation` (`grid-dror`), isolated returns ([`crate::baselines::isolated`]: falling snow,
//! rain drops) are left out of the map and are never ground: without it a flake's `g_rho` of about 0
//! pulls the square's mean below the threshold and the ground under it is lost.

use std::collections::HashMap;

use glam::{Affine3A, Vec3};

use crate::baselines::isolated::{IsolationParams, isolated_returns};
use crate::error::{ClassifyError, Result, check_cloud, is_valid};
use crate::nitsch::{Nitsch, NitschParams, echoes_from_plane0};

/// Parameters of the grid map.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridParams {
    /// Side of a square, metres.
    pub cell_m: f32,
    /// The paper's 15 cm rule, metres.
    pub max_height_m: f32,
    /// Whether to cluster the grid's ground points.
    pub cluster: bool,
    /// Feature, threshold (0.7 in Table I) and clustering parameters.
    pub nitsch: NitschParams,
    /// The particle filter stage: isolated returns left out of the map and never ground (`None` in
    /// Table I's `grid`).
    pub isolation: Option<IsolationParams>,
}

impl Default for GridParams {
    fn default() -> Self {
        Self {
            cell_m: 0.5,
            max_height_m: 0.15,
            cluster: true,
            nitsch: NitschParams { threshold: 0.7, ..Default::default() },
            isolation: None,
        }
    }
}

#[derive(Clone, Copy, Debug, Default)]
struct Square {
    g_sum: f32,
    g_count: u32,
    z_sum: f32,
    z_count: u32,
}

/// The grid accumulation classifier with its map.
#[derive(Clone, Debug)]
pub struct GridAccumulation {
    params: GridParams,
    nitsch: Nitsch,
    map: HashMap<(i32, i32), Square>,
    world: Vec<Vec3>,
    isolated: Vec<bool>,
}

impl GridAccumulation {
    /// A classifier with an empty map.
    pub fn new(params: GridParams) -> Result<Self> {
        if !(params.cell_m.is_finite() && params.cell_m > 0.0) {
            return Err(ClassifyError::invalid("cell_m", params.cell_m, "finite, > 0"));
        }
        if !(params.max_height_m.is_finite() && params.max_height_m >= 0.0) {
            return Err(ClassifyError::invalid("max_height_m", params.max_height_m, "finite, >= 0"));
        }
        if let Some(iso) = &params.isolation {
            if !(iso.radius_multiplier.is_finite() && iso.radius_multiplier >= 0.0) {
                return Err(ClassifyError::invalid(
                    "isolation.radius_multiplier",
                    iso.radius_multiplier,
                    "finite, >= 0",
                ));
            }
            if !(iso.min_radius_m.is_finite() && iso.min_radius_m >= 0.0) {
                return Err(ClassifyError::invalid("isolation.min_radius_m", iso.min_radius_m, "finite, >= 0"));
            }
            if iso.min_neighbours == 0 {
                return Err(ClassifyError::invalid("isolation.min_neighbours", iso.min_neighbours, ">= 1"));
            }
        }
        Ok(Self {
            params,
            nitsch: Nitsch::new(params.nitsch)?,
            map: HashMap::new(),
            world: Vec::new(),
            isolated: Vec::new(),
        })
    }

    /// Number of squares in the map.
    pub fn squares(&self) -> usize {
        self.map.len()
    }

    fn key(&self, p: Vec3) -> (i32, i32) {
        let c = self.params.cell_m;
        ((p.x / c).floor() as i32, (p.y / c).floor() as i32)
    }

    fn is_ground(&self, p: Vec3) -> bool {
        self.map.get(&self.key(p)).is_some_and(|s| {
            s.z_count > 0
                && s.g_sum / s.g_count as f32 >= self.params.nitsch.threshold
                && (p.z - s.z_sum / s.z_count as f32).abs() <= self.params.max_height_m
        })
    }

    /// Accumulates the frame into the map and classifies every cell of `cloud` (all planes).
    pub fn classify(&mut self, cloud: &sim::OrderedCloud, world_from_vehicle: Option<Affine3A>) -> Result<Vec<bool>> {
        check_cloud(cloud)?;
        let pose = match world_from_vehicle {
            Some(t) => t,
            None => {
                self.map.clear();
                Affine3A::IDENTITY
            }
        };
        if !pose.is_finite() {
            return Err(ClassifyError::invalid("world_from_vehicle", "non-finite", "a finite rigid transform"));
        }
        let view = self.nitsch.view(cloud);
        crate::nitsch::features::compute_features(&view, &self.nitsch.params.features, &mut self.nitsch.features);
        self.world.clear();
        self.world.extend(cloud.point_in_vehicle.iter().map(|&p| pose.transform_point3(p)));
        let n0 = cloud.rows * cloud.cols;
        let thr = self.params.nitsch.threshold;
        match &self.params.isolation {
            Some(params) => isolated_returns(cloud, params, &mut self.isolated),
            None => self.isolated.clear(),
        }
        let isolated = |i: usize| self.isolated.get(i).copied().unwrap_or(false);
        for i in 0..n0 {
            let p = self.world[i];
            if !is_valid(p) || isolated(i) {
                continue;
            }
            let g = self.nitsch.features.g_rho[i];
            let key = self.key(p);
            let s = self.map.entry(key).or_default();
            s.g_sum += g;
            s.g_count += 1;
            if g >= thr && g > 0.0 {
                s.z_sum += p.z;
                s.z_count += 1;
            }
        }
        let mut out: Vec<bool> =
            self.world.iter().enumerate().map(|(i, &p)| is_valid(p) && !isolated(i) && self.is_ground(p)).collect();
        if self.params.cluster {
            let candidate = out[..n0].to_vec();
            let ws = &mut ClusterState::default();
            crate::nitsch::cluster::cluster_candidates(
                &view,
                &candidate,
                &self.nitsch.features.normal,
                &self.params.nitsch.clustering,
                &mut ws.0,
            );
            let returns = view.points.iter().filter(|p| is_valid(**p)).count();
            let mut plane0 = vec![false; n0];
            ws.0.decide(view.points, returns, &self.params.nitsch.clustering, &mut plane0);
            out[..n0].copy_from_slice(&plane0);
            echoes_from_plane0(cloud, &plane0, self.params.nitsch.echo_match_m, &mut out);
        }
        Ok(out)
    }
}

#[derive(Default)]
struct ClusterState(crate::nitsch::cluster::ClusterWorkspace);
