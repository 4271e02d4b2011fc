//! `classifier`: ground point classification on ordered LiDAR clouds after Nitsch et al.,
//! *3D Ground Point Classification for Automotive Scenarios*, with the baselines of its Table I
//! and the metrics to compare them.
//!
//! Data flow: an [`sim::OrderedCloud`] -> [`nitsch::neighbours`] (the 8-neighbourhood of Fig. 3 on the grid)
//! -> [`nitsch::features`] (`n`, `n_rho`, `g_rho`, Eq. 1-4) -> [`nitsch::cluster`] (conditional Euclidean clustering
//! and the cluster rules of Sec. III-B) -> a ground decision per cell ([`nitsch`]). The baselines
//! ([`baselines::ransac`], [`baselines::grid`]) and the method live behind one trait in
//! [`methods`], chosen by name from [`METHODS`]. [`metrics`] scores decisions against ground truth;
//! [`ordering`] turns unordered clouds (KITTI `.bin`) into grids; [`recording`] reads any
//! recording the project takes (files, scan directories, ROS 2 bags) as ordered frames with their
//! provenance; [`registry`] resolves a method by name with its model, once; [`synthetic`] builds analytic test
//! clouds. [`mcdaniel`] is the forest method of McDaniel et al. (min-z columns, eight features, a
//! linear SVM); [`sensor_origin`] estimates sensor origins from a cloud's (point, range) pairs.
//!
//! Decisions are one `bool` per cell of the cloud, in the cloud's grid order over all echo planes;
//! cells without a return are never ground.

pub mod baselines;
mod cpu;
pub mod dataset;
pub mod error;
pub mod learned;
pub mod mcdaniel;
pub mod methods;
pub mod metrics;
pub mod model_file;
pub mod nitsch;
pub mod ordering;
pub mod recording;
pub mod registry;
pub mod sensor_origin;
pub mod synthetic;

pub use error::{ClassifyError, Result};
pub use mcdaniel::{McDaniel, McDanielModel, McDanielParams};
pub use methods::{FrameInput, GroundClassifier, METHODS, learned_with_model, mcdaniel_with_model, method_by_name};
pub use metrics::{Confusion, Evaluation, Scores};
pub use model_file::ModelFileError;
pub use nitsch::{Nitsch, NitschParams};
pub use registry::{MethodError, MethodOptions, method, takes_model};
