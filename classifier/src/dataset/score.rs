//! Scores of one method on labelled frames: confusion counts per frame, pooled over the frames and
//! by range band, and the frame means (macro averages) that the Patchwork papers report.

use serde::Serialize;
use serde::ser::SerializeMap;

use crate::metrics::Confusion;

/// Edges of the range bands, metres from the sensor: 0-10, 10-20, 20-40, 40+.
pub const RANGE_BAND_EDGES_M: [f32; 3] = [10.0, 20.0, 40.0];

/// Number of range bands.
pub const RANGE_BANDS: usize = RANGE_BAND_EDGES_M.len() + 1;

/// The band of a range.
pub fn band_of(range_m: f32) -> usize {
    RANGE_BAND_EDGES_M.iter().position(|&e| range_m < e).unwrap_or(RANGE_BAND_EDGES_M.len())
}

/// The name of band `b`: `0-10m`, ..., `40m+`.
pub fn band_name(b: usize) -> String {
    let lo = if b == 0 { 0.0 } else { RANGE_BAND_EDGES_M[b - 1] };
    match RANGE_BAND_EDGES_M.get(b) {
        Some(hi) => format!("{lo}-{hi}m"),
        None => format!("{lo}m+"),
    }
}

/// The measures of one set of counts, as written to JSON and tables (NaN where a denominator is 0,
/// written as `null`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Measures {
    /// Precision.
    pub precision: f64,
    /// Recall.
    pub recall: f64,
    /// F1.
    pub f1: f64,
    /// Ground IoU.
    pub iou: f64,
    /// Accuracy.
    pub accuracy: f64,
}

impl From<&Confusion> for Measures {
    fn from(c: &Confusion) -> Self {
        Self { precision: c.precision(), recall: c.recall(), f1: c.f1(), iou: c.iou(), accuracy: c.accuracy() }
    }
}

fn finite_or_null(v: f64) -> Option<f64> {
    v.is_finite().then_some(v)
}

/// Counts and measures together, serialized as one JSON object.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Counted(pub Confusion);

impl Serialize for Counted {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let m = Measures::from(&self.0);
        let mut map = s.serialize_map(Some(10))?;
        map.serialize_entry("precision", &finite_or_null(m.precision))?;
        map.serialize_entry("recall", &finite_or_null(m.recall))?;
        map.serialize_entry("f1", &finite_or_null(m.f1))?;
        map.serialize_entry("iou", &finite_or_null(m.iou))?;
        map.serialize_entry("accuracy", &finite_or_null(m.accuracy))?;
        map.serialize_entry("tp", &self.0.tp)?;
        map.serialize_entry("fp", &self.0.fp)?;
        map.serialize_entry("tn", &self.0.tn)?;
        map.serialize_entry("fn", &self.0.fn_)?;
        map.serialize_entry("points", &self.0.total())?;
        map.end()
    }
}

/// Bands serialized as `{"0-10m": {...}, ...}`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Bands(pub [Confusion; RANGE_BANDS]);

impl Serialize for Bands {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut map = s.serialize_map(Some(RANGE_BANDS))?;
        for (b, c) in self.0.iter().enumerate() {
            map.serialize_entry(&band_name(b), &Counted(*c))?;
        }
        map.end()
    }
}

/// One frame's scores.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct FrameScore {
    /// Sequence id.
    pub sequence: String,
    /// Frame stem.
    pub frame: String,
    /// Counts over the scored points.
    pub scores: Counted,
    /// Counts by range band.
    pub by_range: Bands,
    /// Points left out by the protocol (ignored classes).
    pub ignored: u64,
    /// No-return points (0, 0, 0 or not finite), left out.
    pub no_returns: u64,
    /// Milliseconds the method took on the frame (classification only; read and ordering apart).
    pub classify_ms: f64,
}

impl FrameScore {
    /// Adds one point: its truth (`None`: left out), the decision, its range from the sensor.
    pub fn add(&mut self, truth: Option<bool>, predicted: bool, range_m: f32) {
        match truth {
            None => self.ignored += 1,
            Some(t) => {
                self.scores.0.add(t, predicted);
                self.by_range.0[band_of(range_m)].add(t, predicted);
            }
        }
    }
}

/// One method's scores over a dataset.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MethodScore {
    /// The method.
    pub method: String,
    /// Every frame, in order.
    pub frames: Vec<FrameScore>,
}

impl MethodScore {
    /// Counts over all frames.
    pub fn pooled(&self) -> Confusion {
        let mut c = Confusion::default();
        for f in &self.frames {
            c.merge(&f.scores.0);
        }
        c
    }

    /// Counts over all frames by range band.
    pub fn by_range(&self) -> [Confusion; RANGE_BANDS] {
        let mut out = [Confusion::default(); RANGE_BANDS];
        for f in &self.frames {
            for (o, c) in out.iter_mut().zip(&f.by_range.0) {
                o.merge(c);
            }
        }
        out
    }

    /// Frame means of precision, recall, F1, IoU and accuracy (frames where a measure is NaN are
    /// left out of its mean): the macro averages of the Patchwork papers' scripts (which average per
    /// sequence first; over one sequence the two agree).
    pub fn frame_means(&self) -> Measures {
        let mean = |f: fn(&Confusion) -> f64| {
            let v: Vec<f64> = self.frames.iter().map(|x| f(&x.scores.0)).filter(|x| x.is_finite()).collect();
            if v.is_empty() { f64::NAN } else { v.iter().sum::<f64>() / v.len() as f64 }
        };
        Measures {
            precision: mean(Confusion::precision),
            recall: mean(Confusion::recall),
            f1: mean(Confusion::f1),
            iou: mean(Confusion::iou),
            accuracy: mean(Confusion::accuracy),
        }
    }

    /// The frame with the lowest F1, if any has one.
    pub fn worst_frame(&self) -> Option<&FrameScore> {
        self.frames
            .iter()
            .filter(|f| f.scores.0.f1().is_finite())
            .min_by(|a, b| a.scores.0.f1().total_cmp(&b.scores.0.f1()))
    }

    /// Mean milliseconds per frame of the classification.
    pub fn mean_classify_ms(&self) -> f64 {
        if self.frames.is_empty() {
            return f64::NAN;
        }
        self.frames.iter().map(|f| f.classify_ms).sum::<f64>() / self.frames.len() as f64
    }
}

impl Serialize for MethodScore {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let m = self.frame_means();
        let mut map = s.serialize_map(Some(6))?;
        map.serialize_entry("pooled", &Counted(self.pooled()))?;
        map.serialize_entry(
            "frame_mean",
            &serde_json::json!({
                "precision": finite_or_null(m.precision), "recall": finite_or_null(m.recall),
                "f1": finite_or_null(m.f1), "iou": finite_or_null(m.iou), "accuracy": finite_or_null(m.accuracy),
            }),
        )?;
        map.serialize_entry("by_range", &Bands(self.by_range()))?;
        map.serialize_entry(
            "worst_frame",
            &self
                .worst_frame()
                .map(|f| serde_json::json!({"sequence": f.sequence, "frame": f.frame, "f1": f.scores.0.f1()})),
        )?;
        map.serialize_entry("mean_classify_ms", &finite_or_null(self.mean_classify_ms()))?;
        map.serialize_entry("frames", &self.frames)?;
        map.end()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bands_and_pooled_and_frame_means() {
        assert_eq!(
            (band_of(0.0), band_of(9.99), band_of(10.0), band_of(39.9), band_of(40.0), band_of(1e9)),
            (0, 0, 1, 2, 3, 3)
        );
        assert_eq!((band_name(0), band_name(3)), ("0-10m".to_string(), "40m+".to_string()));
        let mut a = FrameScore::default();
        // 3 true ground (one missed), 1 false ground, 1 true non-ground, 1 left out.
        a.add(Some(true), true, 5.0);
        a.add(Some(true), true, 15.0);
        a.add(Some(true), false, 50.0);
        a.add(Some(false), true, 5.0);
        a.add(Some(false), false, 5.0);
        a.add(None, true, 5.0);
        assert_eq!(a.scores.0, Confusion { tp: 2, fp: 1, tn: 1, fn_: 1 });
        assert_eq!(a.ignored, 1);
        assert_eq!(a.by_range.0[0], Confusion { tp: 1, fp: 1, tn: 1, fn_: 0 });
        assert_eq!(a.by_range.0[3], Confusion { tp: 0, fp: 0, tn: 0, fn_: 1 });
        let mut b = FrameScore::default();
        b.add(Some(true), true, 5.0);
        let m = MethodScore { method: "x".into(), frames: vec![a, b] };
        assert_eq!(m.pooled(), Confusion { tp: 3, fp: 1, tn: 1, fn_: 1 });
        // Pooled F1 6/8; frame means (4/6 + 1) / 2.
        assert!((m.pooled().f1() - 0.75).abs() < 1e-12);
        assert!((m.frame_means().f1 - (2.0 / 3.0 + 1.0) / 2.0).abs() < 1e-12);
        assert_eq!(m.worst_frame().map(|f| f.scores.0.tp), Some(2));
        let json = serde_json::to_value(&m).unwrap();
        assert_eq!(json["pooled"]["tp"], 3);
        assert!((json["pooled"]["f1"].as_f64().unwrap() - 0.75).abs() < 1e-12);
        assert_eq!(json["by_range"]["40m+"]["fn"], 1);
        assert_eq!(json["frames"].as_array().unwrap().len(), 2);
    }
}
