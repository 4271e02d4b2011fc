//! PLY mesh export/import. TODO
