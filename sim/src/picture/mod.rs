//! Pictures of scans: a bird's-eye view ([`render_bev`]) and a range image ([`render_range`],
//! rows x columns, row 0 at the bottom) of an [`OrderedCloud`], coloured by class, ground truth,
//! range, height or by a classifier's outcome, with a legend and a scale bar in a footer strip,
//! and PNG output written atomically ([`save_png`]).

mod bev;
mod color;
mod draw;
mod range;

pub use bev::{BevOptions, render_bev};
pub use color::{Coloring, OUTCOME_COLORS};
pub use range::{RangeOptions, render_range};

use std::path::Path;

use image::RgbImage;

use crate::error::{Result, SimError};

/// Which picture of a scan to draw.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum View {
    /// Bird's-eye view from above, vehicle at the centre, x (forward) up.
    Bev,
    /// Range image: one pixel row band per grid row (row 0 at the bottom), one column per grid column.
    Range,
}

impl View {
    /// The names [`View::parse`] accepts.
    pub const NAMES: [&'static str; 2] = ["bev", "range"];

    /// Parses `bev` or `range`; other names are refused with the list of allowed ones.
    pub fn parse(name: &str) -> Result<Self> {
        match name {
            "bev" => Ok(View::Bev),
            "range" => Ok(View::Range),
            _ => Err(SimError::invalid("view", name, Self::NAMES.join(", "))),
        }
    }
}

/// Encodes `img` as PNG and writes it to `path` atomically.
pub fn save_png(path: &Path, img: &RgbImage) -> Result<()> {
    let mut bytes = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut bytes), image::ImageFormat::Png)
        .map_err(|e| SimError::io(path, std::io::Error::other(e.to_string())))?;
    crate::io::atomic::write_bytes_atomic(path, &bytes)
}
