//! Range image: the grid as a picture, one band of pixels per row (row 0, the lowest ring, at the
//! bottom) and one pixel column per grid column, black where there is no return.

use super::Raster;

use super::color::{Coloring, paint};
use super::draw::{ScaleBar, fill_rect, nice_floor, with_footer};
use crate::cloud::OrderedCloud;
use crate::error::{Result, SimError};

/// Options of the range image.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct RangeOptions {
    /// Pixel rows per grid row (1 ..= 64); `None` picks one that makes the picture about a
    /// quarter as tall as wide.
    pub row_px: Option<u32>,
    /// Echo plane to draw (0 = first echoes).
    pub plane: usize,
}

/// Draws the range image of `cloud` with `coloring`, legend and a column scale bar.
pub fn render_range(cloud: &OrderedCloud, coloring: &Coloring, opts: &RangeOptions) -> Result<Raster> {
    if cloud.planes > 0 && opts.plane >= cloud.planes {
        return Err(SimError::invalid("plane", opts.plane, format!("0 ..= {}", cloud.planes - 1)));
    }
    let (rows, cols) = (cloud.rows.max(1) as u32, cloud.cols.max(1) as u32);
    if cloud.rows > 16384 || cloud.cols > 16384 {
        return Err(SimError::invalid("grid", format!("{}x{}", cloud.rows, cloud.cols), "at most 16384 x 16384"));
    }
    let (colors, legend) = paint(cloud, coloring)?;
    let col_px = 320u32.div_ceil(cols).max(1);
    let width = cols * col_px;
    let row_px = match opts.row_px {
        Some(r) if (1..=64).contains(&r) => r,
        Some(r) => return Err(SimError::invalid("row_px", r, "1 ..= 64")),
        None => (width / (4 * rows)).clamp(1, 16),
    };
    let height = rows * row_px;
    let mut plot = Raster::new(width, height);
    for row in 0..cloud.rows {
        let y = i64::from(height) - i64::from(row_px) * (row as i64 + 1);
        for col in 0..cloud.cols {
            if let Some(c) = colors[cloud.index(opts.plane, row, col)] {
                fill_rect(&mut plot, col as i64 * i64::from(col_px), y, col_px, row_px, c);
            }
        }
    }
    let bar_cols = nice_floor(0.2 * cols as f32).max(1.0);
    let scale = ScaleBar {
        len_px: (bar_cols * col_px as f32) as u32,
        label: format!("{bar_cols} col{}", if bar_cols == 1.0 { "" } else { "s" }),
    };
    Ok(with_footer(&plot, &legend, Some(&scale)))
}
