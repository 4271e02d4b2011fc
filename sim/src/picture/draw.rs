//! Raster primitives: filled rectangles, 8x8 bitmap text (`font8x8`), the footer with the legend
//! and a scale bar.

use super::Raster;
use font8x8::legacy::BASIC_LEGACY;

use super::color::{Legend, viridis};

/// Footer background.
const FOOTER_BG: [u8; 3] = [40, 40, 40];
/// Text colour.
const TEXT: [u8; 3] = [235, 235, 235];
/// Height of one footer line, pixels.
const LINE_PX: u32 = 14;

/// Fills the rectangle `[x, x + w) x [y, y + h)`, clipped to the image.
pub(crate) fn fill_rect(img: &mut Raster, x: i64, y: i64, w: u32, h: u32, c: [u8; 3]) {
    let (iw, ih) = (i64::from(img.width()), i64::from(img.height()));
    for yy in y.max(0)..(y + i64::from(h)).min(ih) {
        for xx in x.max(0)..(x + i64::from(w)).min(iw) {
            img.put_pixel(xx as u32, yy as u32, c);
        }
    }
}

/// Draws ASCII `text` with its top-left corner at `(x, y)`; returns the width drawn, pixels.
pub(crate) fn text(img: &mut Raster, x: i64, y: i64, s: &str, c: [u8; 3]) -> u32 {
    for (k, ch) in s.chars().enumerate() {
        let glyph = BASIC_LEGACY[(ch as usize).min(127)];
        for (gy, bits) in glyph.iter().enumerate() {
            for gx in 0..8 {
                if bits & (1 << gx) != 0 {
                    fill_rect(img, x + 8 * k as i64 + gx, y + gy as i64, 1, 1, c);
                }
            }
        }
    }
    8 * s.chars().count() as u32
}

/// A scale bar to draw: its length in pixels and its label.
pub(crate) struct ScaleBar {
    /// Bar length, pixels.
    pub len_px: u32,
    /// Label, e.g. `10 m`.
    pub label: String,
}

/// The largest 1, 2 or 5 x 10^k not above `x` (x > 0).
pub(crate) fn nice_floor(x: f32) -> f32 {
    if !(x.is_finite() && x > 0.0) {
        return 1.0;
    }
    let p = 10f32.powf(x.log10().floor());
    let m = x / p;
    p * if m >= 5.0 {
        5.0
    } else if m >= 2.0 {
        2.0
    } else {
        1.0
    }
}

/// Draws one legend item with its top-left corner at `(x, y)`.
type DrawItem<'a> = Box<dyn Fn(&mut Raster, i64, i64) + 'a>;

fn legend_items(legend: &Legend) -> Vec<(u32, DrawItem<'_>)> {
    match legend {
        Legend::Swatches(items) => items
            .iter()
            .map(|(c, name)| {
                let w = 12 + 8 * name.chars().count() as u32 + 12;
                let f: DrawItem = Box::new(move |img, x, y| {
                    fill_rect(img, x, y, 9, 9, *c);
                    text(img, x + 12, y + 1, name, TEXT);
                });
                (w, f)
            })
            .collect(),
        Legend::Ramp { title, lo, hi } => {
            let unit = " m";
            let digits = if hi - lo < 10.0 { 2 } else { 1 };
            let left = format!("{title} {lo:.digits$}");
            let right = format!("{hi:.digits$}{unit}");
            let bar = 128u32;
            let w = 8 * (left.len() + right.len()) as u32 + bar + 16 + 12;
            let f: DrawItem = Box::new(move |img, x, y| {
                let lw = text(img, x, y + 1, &left, TEXT);
                let bx = x + i64::from(lw) + 8;
                for k in 0..bar {
                    fill_rect(img, bx + i64::from(k), y, 1, 9, viridis(k as f32 / (bar - 1) as f32));
                }
                text(img, bx + i64::from(bar) + 8, y + 1, &right, TEXT);
            });
            vec![(w, f)]
        }
    }
}

/// Returns `plot` with a footer strip below it holding the legend (wrapped over lines as needed)
/// and, if given, the scale bar at the right of the last line.
pub(crate) fn with_footer(plot: &Raster, legend: &Legend, scale: Option<&ScaleBar>) -> Raster {
    let width = plot.width().max(160);
    let items = legend_items(legend);
    let scale_w = scale.map_or(0, |s| s.len_px.max(8 * s.label.len() as u32) + 16);
    // Lay out items over lines.
    let mut lines: Vec<Vec<usize>> = vec![Vec::new()];
    let mut x = 8u32;
    for (k, (w, _)) in items.iter().enumerate() {
        if x + w > width && !lines.last().is_some_and(|l| l.is_empty()) {
            lines.push(Vec::new());
            x = 8;
        }
        if let Some(l) = lines.last_mut() {
            l.push(k);
        }
        x += w;
    }
    let last_used: u32 = 8 + lines.last().map_or(0, |l| l.iter().map(|&k| items[k].0).sum());
    let extra_line = scale.is_some() && last_used + scale_w > width;
    let n_lines = lines.len() as u32 + u32::from(extra_line) + u32::from(scale.is_some());
    let footer_h = n_lines * LINE_PX + 8;
    let mut img = Raster::from_pixel(width, plot.height() + footer_h, FOOTER_BG);
    img.paste(plot, 0, 0);
    let top = i64::from(plot.height()) + 6;
    for (li, line) in lines.iter().enumerate() {
        let mut x = 8i64;
        for &k in line {
            (items[k].1)(&mut img, x, top + li as i64 * i64::from(LINE_PX));
            x += i64::from(items[k].0);
        }
    }
    if let Some(s) = scale {
        let y = top + i64::from(n_lines - 2) * i64::from(LINE_PX) + i64::from(LINE_PX);
        let x = i64::from(width) - i64::from(scale_w) - 8 + 8;
        fill_rect(&mut img, x, y, s.len_px, 3, TEXT);
        fill_rect(&mut img, x, y - 3, 1, 9, TEXT);
        fill_rect(&mut img, x + i64::from(s.len_px) - 1, y - 3, 1, 9, TEXT);
        text(&mut img, x, y - 12, &s.label, TEXT);
    }
    img
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nice_floor_picks_1_2_5() {
        assert_eq!(nice_floor(7.3), 5.0);
        assert_eq!(nice_floor(19.0), 10.0);
        assert_eq!(nice_floor(0.3), 0.2);
        assert_eq!(nice_floor(-1.0), 1.0);
    }

    #[test]
    fn text_draws_glyph_pixels() {
        let mut img = Raster::new(16, 8);
        let w = text(&mut img, 0, 0, "I", [255, 255, 255]);
        assert_eq!(w, 8);
        let lit = img.pixels().filter(|p| *p == [255, 255, 255]).count();
        assert!(lit > 5 && lit < 40, "an `I` lights some pixels, got {lit}");
    }
}
