//! Line plots for reports (ROC curves, sweep curves) drawn with `plotters`: axes, tick labels,
//! title and legend, as PNG (bitmap backend, encoded by `image`) or SVG (by the file's extension),
//! written atomically. Text uses DejaVu Sans embedded by the `dejavu` crate, so no system font or
//! font library is needed.

use std::path::Path;
use std::sync::Once;

use anyhow::{Context, bail};
use plotters::prelude::*;

/// One named curve.
#[derive(Clone, Debug)]
pub struct Series {
    /// Legend text.
    pub name: String,
    /// The curve's points `(x, y)`, in drawing order.
    pub points: Vec<(f64, f64)>,
    /// Dashed (`true`) or solid line.
    pub dashed: bool,
}

/// A line plot: axes with labels (units in the labels), a title and one curve per series.
#[derive(Clone, Debug)]
pub struct LinePlot {
    /// Title above the plot.
    pub title: String,
    /// x axis label, with its unit.
    pub x_label: String,
    /// y axis label, with its unit.
    pub y_label: String,
    /// x axis range.
    pub x_range: (f64, f64),
    /// y axis range.
    pub y_range: (f64, f64),
    /// The curves.
    pub series: Vec<Series>,
    /// Also draw the diagonal y = x (chance line of a ROC plot).
    pub diagonal: bool,
}

/// Width and height of the figure, pixels.
const SIZE: (u32, u32) = (800, 640);

/// Registers the embedded font once (plotters looks fonts up by family name).
fn register_fonts() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The embedded font is valid; a failure would only lose the text, never the plot.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, dejavu::sans::regular());
    });
}

/// Line colours, distinguishable in print.
const COLORS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
];

fn draw<DB: DrawingBackend>(plot: &LinePlot, root: DrawingArea<DB, plotters::coord::Shift>) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| anyhow::anyhow!("drawing the plot: {e:?}");
    root.fill(&WHITE).map_err(e)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(&plot.title, ("sans-serif", 24))
        .margin(16)
        .x_label_area_size(48)
        .y_label_area_size(64)
        .build_cartesian_2d(plot.x_range.0..plot.x_range.1, plot.y_range.0..plot.y_range.1)
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc(&plot.x_label)
        .y_desc(&plot.y_label)
        .label_style(("sans-serif", 16))
        .axis_desc_style(("sans-serif", 18))
        .light_line_style(RGBColor(235, 235, 235))
        .draw()
        .map_err(e)?;
    if plot.diagonal {
        let lo = plot.x_range.0.max(plot.y_range.0);
        let hi = plot.x_range.1.min(plot.y_range.1);
        chart
            .draw_series(DashedLineSeries::new(vec![(lo, lo), (hi, hi)], 4, 4, RGBColor(160, 160, 160).into()))
            .map_err(e)?;
    }
    for (k, s) in plot.series.iter().enumerate() {
        let color = COLORS[k % COLORS.len()];
        let style = color.stroke_width(2);
        let anno = if s.dashed {
            chart.draw_series(DashedLineSeries::new(s.points.iter().copied(), 8, 5, style)).map_err(e)?
        } else {
            chart.draw_series(LineSeries::new(s.points.iter().copied(), style)).map_err(e)?
        };
        anno.label(&s.name).legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], color.stroke_width(2)));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerRight)
        .label_font(("sans-serif", 16))
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK)
        .draw()
        .map_err(e)?;
    root.present().map_err(e)?;
    Ok(())
}

/// Draws `plot` to `path`: PNG for `.png`, SVG for `.svg` (written atomically).
pub fn save_line_plot(plot: &LinePlot, path: &Path) -> anyhow::Result<()> {
    register_fonts();
    if plot.series.iter().any(|s| s.points.iter().any(|(x, y)| !x.is_finite() || !y.is_finite())) {
        bail!("plot `{}`: a series holds a non-finite point", plot.title);
    }
    let bytes = match path.extension().and_then(|e| e.to_str()) {
        Some("png") => {
            let (w, h) = SIZE;
            let mut rgb = vec![0u8; (w * h * 3) as usize];
            draw(plot, BitMapBackend::with_buffer(&mut rgb, SIZE).into_drawing_area())?;
            let img = image::RgbImage::from_raw(w, h, rgb).context("plot buffer size")?;
            let mut png = Vec::new();
            img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png).context("encoding the PNG")?;
            png
        }
        Some("svg") => {
            let mut svg = String::new();
            draw(plot, SVGBackend::with_string(&mut svg, SIZE).into_drawing_area())?;
            svg.into_bytes()
        }
        _ => bail!("`{}`: a plot is written as .png or .svg", path.display()),
    };
    sim::io::atomic::write_bytes_atomic(path, &bytes)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn roc() -> LinePlot {
        LinePlot {
            title: "ROC".into(),
            x_label: "false-positive rate".into(),
            y_label: "true-positive rate".into(),
            x_range: (0.0, 1.0),
            y_range: (0.0, 1.0),
            series: vec![Series {
                name: "a (AUC 0.90)".into(),
                points: vec![(0.0, 0.0), (0.1, 0.8), (1.0, 1.0)],
                dashed: false,
            }],
            diagonal: true,
        }
    }

    #[test]
    fn png_and_svg_are_written_with_text() {
        let dir = tempfile::tempdir().unwrap();
        let png = dir.path().join("roc.png");
        save_line_plot(&roc(), &png).unwrap();
        let img = image::open(&png).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), SIZE);
        // The curve's colour is drawn, and dark text pixels exist (title, ticks, legend).
        assert!(img.pixels().any(|p| p.0 == [31, 119, 180]));
        assert!(img.pixels().filter(|p| p.0.iter().all(|&c| c < 60)).count() > 500);
        let svg_path = dir.path().join("roc.svg");
        save_line_plot(&roc(), &svg_path).unwrap();
        let svg = std::fs::read_to_string(&svg_path).unwrap();
        assert!(svg.contains("a (AUC 0.90)") && svg.contains("false-positive rate"));
    }

    #[test]
    fn bad_extension_and_nan_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        assert!(save_line_plot(&roc(), &dir.path().join("roc.jpg")).is_err());
        let mut p = roc();
        p.series[0].points.push((f64::NAN, 0.5));
        let err = save_line_plot(&p, &dir.path().join("roc.png")).unwrap_err().to_string();
        assert!(err.contains("non-finite"), "{err}");
        assert!(!dir.path().join("roc.png").exists());
    }
}
