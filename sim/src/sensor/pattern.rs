//! The firing pattern of one sensor for one frame: a rows x columns grid of beams in the sensor frame.

use glam::Vec3;

/// One beam fired by a sensor: where it starts and where it points, in the sensor frame, and when.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Firing {
    /// Beam origin in the sensor frame, metres (non-zero for HDL-64E per-laser offsets or a nodding lever arm).
    pub origin_in_sensor: Vec3,
    /// Unit beam direction in the sensor frame.
    pub dir_in_sensor: Vec3,
    /// Time of the shot after the start of the frame, seconds.
    pub time_s: f64,
}

/// A frame's worth of beams on the sensor's own ordered grid.
///
/// Ordering rule (every sensor model follows it): row 0 is the lowest beam, rows go up in elevation;
/// column 0 is the left-most azimuth and azimuth decreases with the column index (clockwise seen from
/// above, the scan direction of the LUX and of Velodyne / Ouster spinning sensors). Cells where the
/// sensor fires no beam (a LUX flank outside a layer's azimuth window) are `None` and stay in the grid.
#[derive(Clone, Debug, PartialEq)]
pub struct ScanPattern {
    /// Rows (rings / layers / nodding scans).
    pub rows: usize,
    /// Columns (azimuth steps / beam steps).
    pub cols: usize,
    /// `rows * cols` cells, row-major.
    pub firings: Vec<Option<Firing>>,
    /// Nominal elevation of each row in the sensor frame, radians (for merging rigs).
    pub row_elevation_rad: Vec<f32>,
    /// Nominal azimuth of each column in the sensor frame, radians, decreasing (for merging rigs).
    pub col_azimuth_rad: Vec<f32>,
    /// Duration of one frame, seconds (one revolution, one LUX scan, one full nod).
    pub frame_period_s: f64,
}

impl ScanPattern {
    /// The firing at `(row, col)`.
    pub fn at(&self, row: usize, col: usize) -> Option<&Firing> {
        self.firings[row * self.cols + col].as_ref()
    }

    /// Number of cells that fire a beam.
    pub fn beam_count(&self) -> usize {
        self.firings.iter().filter(|f| f.is_some()).count()
    }
}

/// How the sensor measures a range along a beam, per sensor model. Every effect can be switched off
/// by [`Measurement::ideal`].
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Measurement {
    /// Returns closer than this are dropped, metres.
    pub min_range_m: f32,
    /// Returns farther than this are dropped, metres.
    pub max_range_m: f32,
    /// Standard deviation of Gaussian range noise, metres (0 = none).
    pub range_sigma_m: f32,
    /// Range quantum: reported ranges are rounded to multiples of this, metres (0 = none).
    pub range_quantum_m: f32,
    /// Returns whose incidence angle (beam against surface normal) exceeds this are dropped, degrees
    /// (90 = no grazing dropout).
    pub max_incidence_deg: f32,
    /// Full-angle beam divergence, radians (0 = an ideal thin beam).
    pub beam_divergence_rad: f32,
    /// Largest number of echoes reported per shot (1 = strongest / first only).
    pub max_echoes: u8,
    /// Minimum separation of two echoes along a beam, metres.
    pub echo_separation_m: f32,
    /// Range at which a reflectivity-1 target at normal incidence saturates intensity, metres.
    pub intensity_reference_m: f32,
    /// The datasheet's detection figure, its range: a Lambertian target of
    /// [`Measurement::detection_reflectance`] at normal incidence is detected out to this range in
    /// clear air, metres. With it the sensor's detection threshold (weather) is
    /// `detection_reflectance (intensity_reference_m / detection_range_m)^2`
    /// (`crate::effects::weather::detection_threshold`). Each model's figure and its source:
    /// docs/sensors.md, "Detection figures". Not a range gate: [`Measurement::max_range_m`] is.
    #[serde(default = "default_detection_range_m")]
    pub detection_range_m: f32,
    /// The datasheet's detection figure, its target's reflectance, `(0, 1]` (0.1 = a 10 % target).
    #[serde(default = "default_detection_reflectance")]
    pub detection_reflectance: f32,
}

/// Manifests written before the detection figure existed: the custom model's default (100 m).
fn default_detection_range_m() -> f32 {
    100.0
}

/// Manifests written before the detection figure existed: a 10 % target.
fn default_detection_reflectance() -> f32 {
    0.1
}

impl Measurement {
    /// A spinning sensor's measurement from its range limits, range noise and range quantum, with
    /// the figures every spinning model here shares (representative, not from a datasheet): grazing
    /// returns beyond 89 deg dropped, 3 mrad beam divergence, one echo (a return mode with two
    /// sets [`Measurement::max_echoes`]), 1 m echo separation, intensity saturating at 10 m, and
    /// the detection figure "a 10 % target out to `max_range_m`" until
    /// [`Measurement::with_detection`] sets the datasheet's.
    pub const fn spinning(min_range_m: f32, max_range_m: f32, range_sigma_m: f32, range_quantum_m: f32) -> Self {
        Self {
            min_range_m,
            max_range_m,
            range_sigma_m,
            range_quantum_m,
            max_incidence_deg: 89.0,
            beam_divergence_rad: 0.003,
            max_echoes: 1,
            echo_separation_m: 1.0,
            intensity_reference_m: 10.0,
            detection_range_m: max_range_m,
            detection_reflectance: 0.1,
        }
    }

    /// This measurement with the datasheet's detection figure: a target of `reflectance` (0.1 = a
    /// 10 % Lambertian target) detected out to `range_m`.
    pub const fn with_detection(self, range_m: f32, reflectance: f32) -> Self {
        Self { detection_range_m: range_m, detection_reflectance: reflectance, ..self }
    }

    /// This measurement with every effect off: exact distances, no noise, no quantisation,
    /// no grazing dropout, thin beam, one echo. Min / max range are kept.
    pub fn ideal(self) -> Self {
        Self {
            range_sigma_m: 0.0,
            range_quantum_m: 0.0,
            max_incidence_deg: 90.0,
            beam_divergence_rad: 0.0,
            max_echoes: 1,
            ..self
        }
    }
}
