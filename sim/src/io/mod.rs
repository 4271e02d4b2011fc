//! Files: atomic writes, the scan manifest, and point-cloud formats.

pub mod atomic;
pub mod formats;
