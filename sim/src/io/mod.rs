//! Files: atomic writes, the scan manifest, and point-cloud formats. TODO(io helper): formats.

pub mod atomic;
