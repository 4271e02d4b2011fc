//! The baselines of Table I: RANSAC plane fitting as PCL does it, and grid accumulation of the
//! features over frames; and the particle filter stage of `grid-dror` (isolated returns).

pub mod grid;
pub mod isolated;
pub mod ransac;
