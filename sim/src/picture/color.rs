//! Per-cell colours of a cloud and the legend that explains them.

use crate::cloud::OrderedCloud;
use crate::error::{Result, SimError};
use crate::scene::SemanticClass;

/// How to colour the points of a scan.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Coloring<'a> {
    /// SemanticKITTI class colours.
    Class,
    /// Ground truth: ground vs non-ground.
    Ground,
    /// Measured range (viridis, 0 to the 98th percentile).
    Range,
    /// Height `z` in the vehicle frame (viridis, 2nd to 98th percentile, at least 1 m of span).
    Height,
    /// A classifier's result against ground truth, given its predicted-ground flag per cell
    /// (`planes * rows * cols` entries): true ground, false ground, missed ground, true non-ground.
    Outcome {
        /// Predicted ground, one flag per cell.
        predicted_ground: &'a [bool],
    },
}

impl Coloring<'static> {
    /// The names [`Coloring::parse`] accepts (the outcome colouring needs a prediction, so it has no name).
    pub const NAMES: [&'static str; 4] = ["class", "ground", "range", "height"];

    /// Parses `class`, `ground`, `range` or `height`; other names are refused with the allowed list.
    pub fn parse(name: &str) -> Result<Self> {
        match name {
            "class" => Ok(Coloring::Class),
            "ground" => Ok(Coloring::Ground),
            "range" => Ok(Coloring::Range),
            "height" => Ok(Coloring::Height),
            _ => Err(SimError::invalid("color", name, Self::NAMES.join(", "))),
        }
    }
}

/// Colours of the outcome colouring: true ground, false ground, missed ground, true non-ground.
pub const OUTCOME_COLORS: [([u8; 3], &str); 4] = [
    ([40, 190, 60], "true ground"),
    ([230, 40, 40], "false ground"),
    ([250, 200, 0], "missed ground"),
    ([110, 140, 210], "true non-ground"),
];

const GROUND_COLOR: [u8; 3] = [200, 160, 90];
const NON_GROUND_COLOR: [u8; 3] = [90, 160, 255];

/// What the footer explains.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Legend {
    /// Colour swatches with names.
    Swatches(Vec<([u8; 3], String)>),
    /// A colour ramp from `lo` to `hi` in `unit`, titled.
    Ramp {
        /// Title (`range`, `height`).
        title: &'static str,
        /// Value at the left end.
        lo: f32,
        /// Value at the right end.
        hi: f32,
    },
}

/// Viridis, sampled at 5 anchors and interpolated linearly; `t` in `[0, 1]`.
pub(crate) fn viridis(t: f32) -> [u8; 3] {
    const A: [[f32; 3]; 5] =
        [[68.0, 1.0, 84.0], [59.0, 82.0, 139.0], [33.0, 145.0, 140.0], [94.0, 201.0, 98.0], [253.0, 231.0, 37.0]];
    let t = if t.is_finite() { t.clamp(0.0, 1.0) } else { 0.0 } * 4.0;
    let k = (t.floor() as usize).min(3);
    let f = t - k as f32;
    let mut c = [0u8; 3];
    for (j, out) in c.iter_mut().enumerate() {
        *out = (A[k][j] + (A[k + 1][j] - A[k][j]) * f).round() as u8;
    }
    c
}

/// The `q`-quantile of `values` (finite values only), or `None` if there are none.
fn quantile(mut values: Vec<f32>, q: f32) -> Option<f32> {
    values.retain(|v| v.is_finite());
    if values.is_empty() {
        return None;
    }
    let k = ((values.len() - 1) as f32 * q).round() as usize;
    let (_, v, _) = values.select_nth_unstable_by(k, f32::total_cmp);
    Some(*v)
}

/// Colours every cell (`None` where there is no return) and builds the legend.
pub(crate) fn paint(cloud: &OrderedCloud, coloring: &Coloring) -> Result<(Vec<Option<[u8; 3]>>, Legend)> {
    cloud.check_consistent().map_err(|m| SimError::invalid("cloud", m, "every field planes*rows*cols long"))?;
    let n = cloud.len();
    let hits: Vec<usize> = (0..n).filter(|&i| cloud.has_return(i)).collect();
    let mut colors = vec![None; n];
    let legend = match coloring {
        Coloring::Class => {
            let mut classes: Vec<SemanticClass> = hits.iter().map(|&i| cloud.label[i]).collect();
            classes.sort_unstable();
            classes.dedup();
            for &i in &hits {
                colors[i] = Some(cloud.label[i].color());
            }
            Legend::Swatches(classes.iter().map(|c| (c.color(), c.name().to_string())).collect())
        }
        Coloring::Ground => {
            for &i in &hits {
                colors[i] = Some(if cloud.ground[i] { GROUND_COLOR } else { NON_GROUND_COLOR });
            }
            Legend::Swatches(vec![(GROUND_COLOR, "ground".into()), (NON_GROUND_COLOR, "non-ground".into())])
        }
        Coloring::Range | Coloring::Height => {
            let is_range = matches!(coloring, Coloring::Range);
            let value = |i: usize| if is_range { cloud.range_m[i] } else { cloud.point_in_vehicle[i].z };
            let values: Vec<f32> = hits.iter().map(|&i| value(i)).collect();
            let lo = if is_range { 0.0 } else { quantile(values.clone(), 0.02).unwrap_or(0.0) };
            let hi = quantile(values, 0.98).unwrap_or(1.0);
            // At least 1 m of span, so that flat ground reads as one colour rather than noise.
            let (lo, hi) = if hi - lo >= 1.0 {
                (lo, hi)
            } else if is_range {
                (lo, lo + 1.0)
            } else {
                let mid = 0.5 * (lo + hi);
                (mid - 0.5, mid + 0.5)
            };
            for &i in &hits {
                colors[i] = Some(viridis((value(i) - lo) / (hi - lo)));
            }
            Legend::Ramp { title: if is_range { "range" } else { "height" }, lo, hi }
        }
        Coloring::Outcome { predicted_ground } => {
            if predicted_ground.len() != n {
                return Err(SimError::invalid(
                    "predicted_ground",
                    format!("{} flags", predicted_ground.len()),
                    format!("one per cell ({n})"),
                ));
            }
            for &i in &hits {
                let k = match (cloud.ground[i], predicted_ground[i]) {
                    (true, true) => 0,
                    (false, true) => 1,
                    (true, false) => 2,
                    (false, false) => 3,
                };
                colors[i] = Some(OUTCOME_COLORS[k].0);
            }
            Legend::Swatches(OUTCOME_COLORS.iter().map(|(c, s)| (*c, s.to_string())).collect())
        }
    };
    Ok((colors, legend))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn viridis_ends_and_middle() {
        assert_eq!(viridis(0.0), [68, 1, 84]);
        assert_eq!(viridis(1.0), [253, 231, 37]);
        assert_eq!(viridis(0.5), [33, 145, 140]);
        assert_eq!(viridis(f32::NAN), [68, 1, 84]);
    }

    #[test]
    fn parse_lists_allowed_names() {
        let e = Coloring::parse("rainbow").unwrap_err().to_string();
        assert!(e.contains("class, ground, range, height"), "{e}");
    }
}
