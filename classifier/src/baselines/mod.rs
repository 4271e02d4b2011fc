//! The baselines of Table I: RANSAC plane fitting as PCL does it, and grid accumulation of the
//! features over frames.

pub mod grid;
pub mod ransac;
