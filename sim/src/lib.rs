//! `sim`: the LiDAR simulator.
//!
//! Data flows one way through the modules:
//! [`scene`] (labelled triangle meshes) -> [`sensor`] (firing patterns) and [`rig`] (mounts)
//! -> [`cast`] (watertight ray casting) -> [`effects`] (noise, quantisation, dropout, intensity)
//! -> [`cloud`] (the ordered labelled cloud) -> [`io`] (files).
//! [`scan`] runs that pipeline for a rig over several frames with [`motion`] (ego motion).

pub mod cast;
pub mod cloud;
pub mod effects;
pub mod error;
pub mod io;
pub mod layout;
pub mod motion;
pub mod noise;
pub mod picture;
pub mod rig;
pub mod scan;
pub mod scene;
pub mod sensor;

pub use cloud::OrderedCloud;
pub use error::SimError;
pub use rig::{MountedSensor, Rig};
pub use scene::{SceneMesh, SemanticClass, Surface};
