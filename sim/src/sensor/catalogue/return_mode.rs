//! Return modes of spinning sensors, defined once for every model: which echoes of a shot the
//! sensor reports, and where they sit in the ordered grid and in each output format.

use serde::{Deserialize, Serialize};

/// Which echoes of one shot a sensor reports (TOML `return_mode = "strongest" | "last" | "dual"`).
///
/// # In the ordered grid
/// The grid has echo **planes** ([`crate::OrderedCloud`]`::planes`, index
/// `(plane * rows + row) * cols + col`): a single-return mode gives one plane; `Dual` gives two.
/// Plane 0 holds each shot's first reported echo, plane 1 the second one of the same shot (same
/// row, column, ring and time) where the shot had two echoes at least
/// [`crate::sensor::Measurement::echo_separation_m`] apart, else a no-return cell; the `echo`
/// field is the plane (0 or 1). This is the layout the multi-echo LUX already uses
/// (`max_echoes = 3`: planes 0, 1, 2).
///
/// The simulator orders a shot's echoes by range (plane 0 the nearest): in `Dual` the two planes
/// are the two echoes the sensors report (Velodyne and Hesai: strongest and last; Ouster: the two
/// strongest), stored nearest first. For `Strongest` and `Last` the one simulated echo is the
/// nearest surface a beam hits; where a beam straddles an edge and the sensor would pick the far
/// surface (`Last`) or the brighter one (`Strongest`), the simulator does not (yet) choose
/// differently.
///
/// # In weather
/// The medium's echo (a fog return, a drop, a flake) in front of the beam's surface is chosen by
/// the mode ([`crate::effects::weather`], "Return modes"): `Strongest` reports it instead of the
/// surface when it is the stronger; `Last` reports the surface whenever it is detectable; `Dual`
/// reports the medium's echo in plane 0 and the surface behind it in plane 1.
///
/// # In each output format
/// - our PCD: HEIGHT = rows x planes, plane `k` occupies rows `k * R .. (k + 1) * R`, field `echo`;
/// - PLY, LAS, KITTI `.bin`: every return of every plane, plane by plane (LAS `return_number` =
///   echo + 1, `number_of_returns` = the returns of that shot);
/// - the drivers' PCD layouts (`velodyne`, `ouster`) and their ROS 2 clouds: plane 0 only (the
///   ROS 2 drivers of Velodyne and Ouster publish one return per shot per cloud; nebula's
///   Hesai / RoboSense clouds mark the return in `return_type`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ReturnMode {
    /// One echo per shot: the strongest.
    Strongest,
    /// One echo per shot: the last (farthest).
    Last,
    /// Two echoes per shot (two echo planes).
    Dual,
}

impl ReturnMode {
    /// Every mode, in the order of [`ReturnMode::name`]s in error messages.
    pub const ALL: [ReturnMode; 3] = [ReturnMode::Strongest, ReturnMode::Last, ReturnMode::Dual];

    /// The mode's TOML name.
    pub fn name(self) -> &'static str {
        match self {
            ReturnMode::Strongest => "strongest",
            ReturnMode::Last => "last",
            ReturnMode::Dual => "dual",
        }
    }

    /// Echoes reported per shot (= echo planes of the grid): 1, or 2 for `Dual`.
    pub fn echoes(self) -> u8 {
        match self {
            ReturnMode::Strongest | ReturnMode::Last => 1,
            ReturnMode::Dual => 2,
        }
    }

    /// The names of `modes`, comma separated (for error messages and docs).
    pub fn names(modes: &[ReturnMode]) -> String {
        modes.iter().map(|m| m.name()).collect::<Vec<_>>().join(", ")
    }
}
