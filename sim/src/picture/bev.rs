//! Bird's-eye view: the returns seen from above, vehicle origin at the centre, x (forward) up and
//! y (left) to the left, with a metric scale bar.

use super::Raster;

use super::color::{Coloring, paint};
use super::draw::{ScaleBar, fill_rect, nice_floor, with_footer};
use crate::cloud::OrderedCloud;
use crate::error::{Result, SimError};

/// Options of the bird's-eye view.
#[derive(Clone, Debug, PartialEq)]
pub struct BevOptions {
    /// Width and height of the square plot, pixels (16 ..= 8192).
    pub size_px: u32,
    /// Half the side of the square shown, metres; `None` fits the 98th percentile of the
    /// horizontal distances of the returns (at least 5 m).
    pub half_extent_m: Option<f32>,
    /// Side of the square drawn per point, pixels (1 ..= 16).
    pub point_px: u32,
}

impl Default for BevOptions {
    fn default() -> Self {
        Self { size_px: 800, half_extent_m: None, point_px: 2 }
    }
}

/// Draws the bird's-eye view of `cloud` with `coloring`, legend and scale bar.
pub fn render_bev(cloud: &OrderedCloud, coloring: &Coloring, opts: &BevOptions) -> Result<Raster> {
    if !(16..=8192).contains(&opts.size_px) {
        return Err(SimError::invalid("size_px", opts.size_px, "16 ..= 8192"));
    }
    if !(1..=16).contains(&opts.point_px) {
        return Err(SimError::invalid("point_px", opts.point_px, "1 ..= 16"));
    }
    let (colors, legend) = paint(cloud, coloring)?;
    let half = match opts.half_extent_m {
        Some(h) if h.is_finite() && h > 0.0 && h <= 1.0e5 => h,
        Some(h) => return Err(SimError::invalid("half_extent_m", h, "0 < x <= 100000")),
        None => {
            let mut d: Vec<f32> = (0..cloud.len())
                .filter(|&i| cloud.has_return(i))
                .map(|i| cloud.point_in_vehicle[i].truncate().abs().max_element())
                .filter(|v| v.is_finite())
                .collect();
            let q = if d.is_empty() {
                5.0
            } else {
                let k = ((d.len() - 1) as f32 * 0.98).round() as usize;
                *d.select_nth_unstable_by(k, f32::total_cmp).1
            };
            (q * 1.05).clamp(5.0, 1.0e5)
        }
    };
    let size = opts.size_px;
    let m_per_px = 2.0 * half / size as f32;
    let c = size as f32 / 2.0;
    let mut plot = Raster::from_pixel(size, size, [18, 18, 18]);
    let off = (opts.point_px / 2) as i64;
    for (i, col) in colors.iter().enumerate() {
        let Some(col) = col else { continue };
        let p = cloud.point_in_vehicle[i];
        let u = c - p.y / m_per_px;
        let v = c - p.x / m_per_px;
        if !(u.is_finite() && v.is_finite()) || u < -1.0 || v < -1.0 || u > size as f32 || v > size as f32 {
            continue;
        }
        fill_rect(&mut plot, u.floor() as i64 - off, v.floor() as i64 - off, opts.point_px, opts.point_px, *col);
    }
    // Vehicle origin: a small white cross.
    let ci = c as i64;
    fill_rect(&mut plot, ci - 4, ci, 9, 1, [255, 255, 255]);
    fill_rect(&mut plot, ci, ci - 4, 1, 9, [255, 255, 255]);
    let bar_m = nice_floor(0.2 * 2.0 * half);
    let scale = ScaleBar { len_px: (bar_m / m_per_px).round().max(1.0) as u32, label: format!("{bar_m} m") };
    Ok(with_footer(&plot, &legend, Some(&scale)))
}
