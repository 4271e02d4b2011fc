//! Organized PCD files laid out as the ROS drivers write them, so that our scans can stand in for
//! real recordings with ground truth ([`PcdLayout`], `groundtruth scan --pcd-layout`).
//!
//! - `groundtruth`: our own layout ([`super::encode`]): rows bottom-first, every field, NaN
//!   no-returns, the `# groundtruth` grid line.
//! - `velodyne` (velodyne_pointcloud's organized `PointXYZIRT`): `x y z intensity` (F4),
//!   `ring` (U2, 0 = the lowest beam), `time` (F4, seconds after the frame's first shot), HEIGHT =
//!   rings with row `r` = ring `r` (bottom-first), WIDTH = columns, NaN x y z where there is no
//!   return.
//! - `ouster` (ouster-ros' `Point`): `x y z intensity` (F4), `t` (U4, nanoseconds after the frame's
//!   first shot), `reflectivity` (U2), `ring` (U2, 0 = the **top** beam), `ambient` (U2), `range`
//!   (U4, millimetres), HEIGHT = beams with row 0 = ring 0 = the top beam, WIDTH = columns, and
//!   no-return cells as zeros (x y z and range 0).
//!
//! Both driver layouts add our `label` (U4, SemanticKITTI class) so the file carries its ground
//! truth (tools that do not know the field ignore it), write intensity scaled to 0..255, hold plane
//! 0 only (the drivers have no echo planes) and, given `sensor_from_vehicle`, hold the points in the
//! sensor frame as the drivers do (`groundtruth scan` does so for single-sensor rigs, as for KITTI:
//! manifest `kitti_frame`), else in the cloud's frame. They carry no `# groundtruth` line: a reader must tell the layout from the
//! data, as with a real file.

use std::path::Path;

use glam::Affine3A;

use crate::cloud::OrderedCloud;
use crate::error::{Result, SimError};

/// The organized PCD layouts the writer knows.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PcdLayout {
    /// Our own layout (bottom-first, every field).
    #[default]
    Groundtruth,
    /// velodyne_pointcloud's organized `PointXYZIRT` (bottom-first, NaN no-returns).
    Velodyne,
    /// ouster-ros' `Point` (top-first, zero no-returns, range in millimetres).
    Ouster,
}

impl PcdLayout {
    /// The names [`PcdLayout::parse`] accepts.
    pub const NAMES: [&'static str; 3] = ["groundtruth", "velodyne", "ouster"];

    /// The layout called `name` (one of [`PcdLayout::NAMES`]); others are refused naming them.
    pub fn parse(name: &str) -> Result<Self> {
        match name.trim().to_ascii_lowercase().as_str() {
            "groundtruth" => Ok(PcdLayout::Groundtruth),
            "velodyne" => Ok(PcdLayout::Velodyne),
            "ouster" => Ok(PcdLayout::Ouster),
            _ => Err(SimError::invalid("pcd-layout", name, Self::NAMES.join(", "))),
        }
    }

    /// The layout's name.
    pub fn name(self) -> &'static str {
        match self {
            PcdLayout::Groundtruth => "groundtruth",
            PcdLayout::Velodyne => "velodyne",
            PcdLayout::Ouster => "ouster",
        }
    }
}

fn header(fields: &[(&str, char, usize)], width: usize, height: usize) -> String {
    let names: Vec<&str> = fields.iter().map(|f| f.0).collect();
    let sizes: Vec<String> = fields.iter().map(|f| f.2.to_string()).collect();
    let types: Vec<String> = fields.iter().map(|f| f.1.to_string()).collect();
    format!(
        "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS {}\nSIZE {}\nTYPE {}\nCOUNT {}\nWIDTH {width}\nHEIGHT {height}\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {}\nDATA binary\n",
        names.join(" "),
        sizes.join(" "),
        types.join(" "),
        vec!["1"; fields.len()].join(" "),
        width * height
    )
}

/// Encodes plane 0 of `cloud` in `layout` (binary; `ascii` applies to our own layout only; the
/// driver layouts move points by `sensor_from_vehicle` where given).
pub fn encode_layout(
    cloud: &OrderedCloud,
    layout: PcdLayout,
    ascii: bool,
    sensor_from_vehicle: Option<&Affine3A>,
) -> Result<Vec<u8>> {
    if layout == PcdLayout::Groundtruth {
        return super::encode(cloud, ascii);
    }
    cloud.check_consistent().map_err(|m| SimError::invalid("cloud", m, "every field planes*rows*cols long"))?;
    let (rows, cols) = (cloud.rows, cloud.cols);
    let n = rows * cols;
    let t0 = (0..n).filter(|&i| cloud.has_return(i)).map(|i| cloud.time_s[i]).fold(f64::INFINITY, f64::min);
    let t0 = if t0.is_finite() { t0 } else { 0.0 };
    let to_file = |p: glam::Vec3| sensor_from_vehicle.map_or(p, |t| t.transform_point3(p));
    let intensity = |i: usize| (cloud.intensity[i].clamp(0.0, 1.0) * 255.0).round();
    let mut out;
    match layout {
        PcdLayout::Velodyne => {
            let fields = [
                ("x", 'F', 4),
                ("y", 'F', 4),
                ("z", 'F', 4),
                ("intensity", 'F', 4),
                ("ring", 'U', 2),
                ("time", 'F', 4),
                ("label", 'U', 4),
            ];
            let h = header(&fields, cols, rows);
            out = Vec::with_capacity(h.len() + n * 26);
            out.extend_from_slice(h.as_bytes());
            for r in 0..rows {
                for c in 0..cols {
                    let i = r * cols + c;
                    let hit = cloud.has_return(i);
                    let p = to_file(cloud.point_in_vehicle[i]);
                    for v in [p.x, p.y, p.z] {
                        out.extend_from_slice(&(if hit { v } else { f32::NAN }).to_le_bytes());
                    }
                    out.extend_from_slice(&(if hit { intensity(i) } else { 0.0 }).to_le_bytes());
                    out.extend_from_slice(&(r as u16).to_le_bytes());
                    out.extend_from_slice(&((cloud.time_s[i] - t0) as f32).to_le_bytes());
                    out.extend_from_slice(&u32::from(if hit { cloud.label[i].0 } else { 0 }).to_le_bytes());
                }
            }
        }
        PcdLayout::Ouster => {
            let fields = [
                ("x", 'F', 4),
                ("y", 'F', 4),
                ("z", 'F', 4),
                ("intensity", 'F', 4),
                ("t", 'U', 4),
                ("reflectivity", 'U', 2),
                ("ring", 'U', 2),
                ("ambient", 'U', 2),
                ("range", 'U', 4),
                ("label", 'U', 4),
            ];
            let h = header(&fields, cols, rows);
            out = Vec::with_capacity(h.len() + n * 34);
            out.extend_from_slice(h.as_bytes());
            for k in 0..rows {
                let r = rows - 1 - k;
                for c in 0..cols {
                    let i = r * cols + c;
                    let hit = cloud.has_return(i);
                    let p = if hit { to_file(cloud.point_in_vehicle[i]) } else { glam::Vec3::ZERO };
                    for v in [p.x, p.y, p.z] {
                        out.extend_from_slice(&v.to_le_bytes());
                    }
                    out.extend_from_slice(&(if hit { intensity(i) } else { 0.0 }).to_le_bytes());
                    let t = ((cloud.time_s[i] - t0).max(0.0) * 1e9).round().min(u32::MAX as f64) as u32;
                    out.extend_from_slice(&t.to_le_bytes());
                    out.extend_from_slice(&(if hit { intensity(i) as u16 } else { 0 }).to_le_bytes());
                    out.extend_from_slice(&(k as u16).to_le_bytes());
                    out.extend_from_slice(&0u16.to_le_bytes());
                    let mm =
                        if hit { (cloud.range_m[i] * 1000.0).round().clamp(0.0, u32::MAX as f32) as u32 } else { 0 };
                    out.extend_from_slice(&mm.to_le_bytes());
                    out.extend_from_slice(&u32::from(if hit { cloud.label[i].0 } else { 0 }).to_le_bytes());
                }
            }
        }
        PcdLayout::Groundtruth => unreachable!("handled above"),
    }
    Ok(out)
}

/// Writes `cloud` in `layout` at `path` (atomically). Returns the point count (`WIDTH * HEIGHT`).
pub fn write_layout(
    path: &Path,
    cloud: &OrderedCloud,
    layout: PcdLayout,
    ascii: bool,
    sensor_from_vehicle: Option<&Affine3A>,
) -> Result<usize> {
    let bytes = encode_layout(cloud, layout, ascii, sensor_from_vehicle)?;
    super::super::atomic::write_bytes_atomic(path, &bytes)?;
    Ok(if layout == PcdLayout::Groundtruth { cloud.len() } else { cloud.rows * cloud.cols })
}
