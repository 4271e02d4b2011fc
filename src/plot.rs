//! Plots for reports drawn with `plotters`: line plots (ROC curves, sweep curves; optionally a
//! shaded band around each line, e.g. the spread over seeds: [`save_line_plot_with_bands`]) and
//! heat maps of a value over two parameters with a colour bar ([`save_heat_map`]). Axes, tick
//! labels, title and legend, as PNG (bitmap backend, encoded by `image`) or SVG (by the file's
//! extension), written atomically. Text uses DejaVu Sans embedded by the `dejavu` crate, so no
//! system font or font library is needed.

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

/// Title font size: 24 px, smaller for titles that would not fit the figure's width (DejaVu
/// Sans averages about 0.55 em per character).
fn title_size(title: &str) -> u32 {
    let chars = title.chars().count().max(1) as f64;
    let fit = (f64::from(SIZE.0) - 24.0) / (0.55 * chars);
    fit.clamp(12.0, 24.0) as u32
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

/// A shaded band around series `k` of a line plot: `(x, low, high)` points in x order.
pub type Band = Vec<(f64, f64, f64)>;

/// A heat map: one value per (x, y) cell of a grid of parameter values, with a colour bar.
#[derive(Clone, Debug)]
pub struct HeatMap {
    /// Title above the plot.
    pub title: String,
    /// x axis label, with its unit.
    pub x_label: String,
    /// y axis label, with its unit.
    pub y_label: String,
    /// Colour bar label (the value), with its unit.
    pub value_label: String,
    /// The x values of the columns, increasing.
    pub xs: Vec<f64>,
    /// The y values of the rows, increasing.
    pub ys: Vec<f64>,
    /// `values[row][col]` at `(xs[col], ys[row])`; `None` where nothing was measured (drawn grey).
    pub values: Vec<Vec<Option<f64>>>,
}

fn draw_with_bands<DB: DrawingBackend>(
    plot: &LinePlot,
    bands: &[Band],
    root: DrawingArea<DB, plotters::coord::Shift>,
) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| anyhow::anyhow!("drawing the plot: {e:?}");
    root.fill(&WHITE).map_err(e)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(&plot.title, ("sans-serif", title_size(&plot.title)))
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
    for (k, band) in bands.iter().enumerate().filter(|(_, b)| b.len() > 1) {
        let color = COLORS[k % COLORS.len()];
        let mut outline: Vec<(f64, f64)> = band.iter().map(|&(x, lo, _)| (x, lo)).collect();
        outline.extend(band.iter().rev().map(|&(x, _, hi)| (x, hi)));
        chart.draw_series(std::iter::once(Polygon::new(outline, color.mix(0.18).filled()))).map_err(e)?;
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

/// A figure that can be drawn on either backend.
trait Figure {
    fn draw_on<DB: DrawingBackend>(&self, root: DrawingArea<DB, plotters::coord::Shift>) -> anyhow::Result<()>
    where
        DB::ErrorType: 'static;
}

impl Figure for (&LinePlot, &[Band]) {
    fn draw_on<DB: DrawingBackend>(&self, root: DrawingArea<DB, plotters::coord::Shift>) -> anyhow::Result<()>
    where
        DB::ErrorType: 'static,
    {
        draw_with_bands(self.0, self.1, root)
    }
}

impl Figure for HeatMap {
    fn draw_on<DB: DrawingBackend>(&self, root: DrawingArea<DB, plotters::coord::Shift>) -> anyhow::Result<()>
    where
        DB::ErrorType: 'static,
    {
        draw_heat_map(self, root)
    }
}

/// Renders `figure` as PNG or SVG by `path`'s extension and writes it atomically.
fn save(figure: &impl Figure, path: &Path) -> anyhow::Result<()> {
    register_fonts();
    let bytes = match path.extension().and_then(|e| e.to_str()) {
        Some("png") => {
            let (w, h) = SIZE;
            let mut rgb = vec![0u8; (w * h * 3) as usize];
            figure.draw_on(BitMapBackend::with_buffer(&mut rgb, SIZE).into_drawing_area())?;
            let img = sim::picture::Raster::from_raw(w, h, rgb).context("plot buffer size")?;
            img.to_png().context("encoding the PNG")?
        }
        Some("svg") => {
            let mut svg = String::new();
            figure.draw_on(SVGBackend::with_string(&mut svg, SIZE).into_drawing_area())?;
            svg.into_bytes()
        }
        _ => bail!("`{}`: a plot is written as .png or .svg", path.display()),
    };
    sim::io::atomic::write_bytes_atomic(path, &bytes)?;
    Ok(())
}

/// Draws `plot` to `path`: PNG for `.png`, SVG for `.svg` (written atomically).
pub fn save_line_plot(plot: &LinePlot, path: &Path) -> anyhow::Result<()> {
    save_line_plot_with_bands(plot, &[], path)
}

/// Draws `plot` with `bands[k]` shaded (light, in the line's colour) behind series `k` (fewer
/// bands than series leave the rest without one) to `path`, like [`save_line_plot`].
pub fn save_line_plot_with_bands(plot: &LinePlot, bands: &[Band], path: &Path) -> anyhow::Result<()> {
    if plot.series.iter().any(|s| s.points.iter().any(|(x, y)| !x.is_finite() || !y.is_finite())) {
        bail!("plot `{}`: a series holds a non-finite point", plot.title);
    }
    if bands.iter().flatten().any(|(x, lo, hi)| !x.is_finite() || !lo.is_finite() || !hi.is_finite()) {
        bail!("plot `{}`: a band holds a non-finite point", plot.title);
    }
    if bands.len() > plot.series.len() {
        bail!("plot `{}`: {} bands for {} series", plot.title, bands.len(), plot.series.len());
    }
    save(&(plot, bands), path)
}

/// Draws `map` to `path` (PNG or SVG by the extension, written atomically). Refused: an empty
/// grid, a values grid not `ys.len()` x `xs.len()`, non-finite or non-increasing axis values, a
/// non-finite value.
pub fn save_heat_map(map: &HeatMap, path: &Path) -> anyhow::Result<()> {
    let increasing = |v: &[f64]| v.iter().all(|x| x.is_finite()) && v.windows(2).all(|w| w[0] < w[1]);
    if map.xs.is_empty() || map.ys.is_empty() {
        bail!("heat map `{}`: no cells", map.title);
    }
    if !increasing(&map.xs) || !increasing(&map.ys) {
        bail!("heat map `{}`: axis values must be finite and increasing", map.title);
    }
    if map.values.len() != map.ys.len() || map.values.iter().any(|r| r.len() != map.xs.len()) {
        bail!("heat map `{}`: values must be {} rows of {} columns", map.title, map.ys.len(), map.xs.len());
    }
    if map.values.iter().flatten().flatten().any(|v| !v.is_finite()) {
        bail!("heat map `{}`: a value is not finite", map.title);
    }
    save(map, path)
}

/// Cell edges around increasing centres: midpoints, and half a step beyond the ends.
fn edges(c: &[f64]) -> Vec<f64> {
    if c.len() == 1 {
        return vec![c[0] - 0.5, c[0] + 0.5];
    }
    let mut e = vec![c[0] - (c[1] - c[0]) / 2.0];
    e.extend(c.windows(2).map(|w| (w[0] + w[1]) / 2.0));
    e.push(c[c.len() - 1] + (c[c.len() - 1] - c[c.len() - 2]) / 2.0);
    e
}

/// The viridis colour map at `t` in [0, 1] (linear between 5 anchors).
pub fn viridis(t: f64) -> RGBColor {
    const A: [(f64, f64, f64); 5] =
        [(68.0, 1.0, 84.0), (59.0, 82.0, 139.0), (33.0, 145.0, 140.0), (94.0, 201.0, 98.0), (253.0, 231.0, 37.0)];
    let t = if t.is_finite() { t.clamp(0.0, 1.0) } else { 0.0 } * 4.0;
    let k = (t.floor() as usize).min(3);
    let f = t - k as f64;
    let mix = |a: f64, b: f64| (a + (b - a) * f).round() as u8;
    RGBColor(mix(A[k].0, A[k + 1].0), mix(A[k].1, A[k + 1].1), mix(A[k].2, A[k + 1].2))
}

fn draw_heat_map<DB: DrawingBackend>(map: &HeatMap, root: DrawingArea<DB, plotters::coord::Shift>) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| anyhow::anyhow!("drawing the heat map: {e:?}");
    root.fill(&WHITE).map_err(e)?;
    let root = root.titled(&map.title, ("sans-serif", title_size(&map.title))).map_err(e)?;
    let (main, bar) = root.split_horizontally(SIZE.0 - 130);
    let (xe, ye) = (edges(&map.xs), edges(&map.ys));
    let mut chart = ChartBuilder::on(&main)
        .margin(16)
        .x_label_area_size(48)
        .y_label_area_size(64)
        .build_cartesian_2d(xe[0]..xe[xe.len() - 1], ye[0]..ye[ye.len() - 1])
        .map_err(e)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(&map.x_label)
        .y_desc(&map.y_label)
        .label_style(("sans-serif", 16))
        .axis_desc_style(("sans-serif", 18))
        .draw()
        .map_err(e)?;
    let finite: Vec<f64> = map.values.iter().flatten().flatten().copied().collect();
    let lo = finite.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = finite.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let (lo, hi) = if finite.is_empty() {
        (0.0, 1.0)
    } else if hi > lo {
        (lo, hi)
    } else {
        (lo - 0.5, lo + 0.5)
    };
    let t = |v: f64| (v - lo) / (hi - lo);
    let label_cells = map.xs.len() <= 12 && map.ys.len() <= 16;
    for (r, row) in map.values.iter().enumerate() {
        for (c, v) in row.iter().enumerate() {
            let color = v.map_or(RGBColor(200, 200, 200), |v| viridis(t(v)));
            let cell = Rectangle::new([(xe[c], ye[r]), (xe[c + 1], ye[r + 1])], color.filled());
            chart.draw_series(std::iter::once(cell)).map_err(e)?;
            if let (true, Some(v)) = (label_cells, v) {
                let ink = if t(*v) > 0.6 { BLACK } else { WHITE };
                let style = ("sans-serif", 13).into_font().color(&ink).pos(plotters::style::text_anchor::Pos::new(
                    plotters::style::text_anchor::HPos::Center,
                    plotters::style::text_anchor::VPos::Center,
                ));
                let text = Text::new(format!("{v:.3}"), (map.xs[c], map.ys[r]), style);
                chart.draw_series(std::iter::once(text)).map_err(e)?;
            }
        }
    }
    let mut scale = ChartBuilder::on(&bar)
        .margin_top(16)
        .margin_bottom(64)
        .margin_right(8)
        .y_label_area_size(64)
        .build_cartesian_2d(0.0..1.0, lo..hi)
        .map_err(e)?;
    scale
        .configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_desc(&map.value_label)
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 16))
        .draw()
        .map_err(e)?;
    let steps = 64;
    scale
        .draw_series((0..steps).map(|k| {
            let (a, b) = (k as f64 / steps as f64, (k + 1) as f64 / steps as f64);
            Rectangle::new([(0.0, lo + a * (hi - lo)), (1.0, lo + b * (hi - lo))], viridis((a + b) / 2.0).filled())
        }))
        .map_err(e)?;
    root.present().map_err(e)?;
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
    fn bands_and_heat_maps_are_drawn() {
        let dir = tempfile::tempdir().unwrap();
        let png = dir.path().join("band.png");
        let band = vec![(0.0, -0.1, 0.1), (0.1, 0.6, 0.9), (1.0, 0.9, 1.0)];
        save_line_plot_with_bands(&roc(), &[band], &png).unwrap();
        let img = image::open(&png).unwrap().to_rgb8();
        // The band is the line colour mixed 18 % over white.
        let light = |c: u8| (255.0 - 0.18 * (255.0 - c as f64)).round() as i32;
        let near =
            |p: &image::Rgb<u8>| p.0.iter().zip([31u8, 119, 180]).all(|(&a, b)| (a as i32 - light(b)).abs() <= 2);
        assert!(img.pixels().filter(|p| near(p)).count() > 500);
        let map = HeatMap {
            title: "F1".into(),
            x_label: "pitch (deg)".into(),
            y_label: "height (m)".into(),
            value_label: "F1".into(),
            xs: vec![-2.0, 0.0, 2.0],
            ys: vec![1.2, 1.6],
            values: vec![vec![Some(0.5), Some(0.7), None], vec![Some(0.9), Some(1.0), Some(0.8)]],
        };
        let png = dir.path().join("heat.png");
        save_heat_map(&map, &png).unwrap();
        let img = image::open(&png).unwrap().to_rgb8();
        // The lowest and highest values take the two ends of the colour map; missing is grey.
        for c in [viridis(0.0), viridis(1.0), RGBColor(200, 200, 200)] {
            assert!(img.pixels().filter(|p| p.0 == [c.0, c.1, c.2]).count() > 1000, "{c:?}");
        }
        let svg = dir.path().join("heat.svg");
        save_heat_map(&map, &svg).unwrap();
        assert!(std::fs::read_to_string(&svg).unwrap().contains("height (m)"));
        let mut bad = map.clone();
        bad.values.pop();
        assert!(save_heat_map(&bad, &png).is_err());
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
