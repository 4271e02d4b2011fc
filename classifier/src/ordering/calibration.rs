//! Calibration files: a sensor's own per-laser elevations (and azimuth and origin offsets), so a
//! user's unit is ordered with its own angles ([`Calibration::to_table`]). Formats, chosen by the
//! file's extension:
//!
//! - `.toml`: our documented format. Angles in degrees, offsets in metres; every field but
//!   `elevation_deg` optional (0):
//!   ```toml
//!   columns = 2083                      # optional: columns per turn
//!   [[lasers]]
//!   elevation_deg = 2.0
//!   azimuth_offset_deg = -3.1           # left positive
//!   horizontal_offset_m = 0.026         # beam origin left of the beam
//!   vertical_offset_m = 0.21            # beam origin above the sensor origin
//!   ```
//! - `.txt`: one laser per line, `elevation_deg [azimuth_offset_deg]`, blank lines and `#` comments
//!   ignored.
//! - `.yaml` / `.yml`: the velodyne driver's calibration (`lasers:` with `laser_id`,
//!   `vert_correction` and `rot_correction` in radians, optional `horiz_offset_correction` and
//!   `vert_offset_correction` in metres; `num_lasers`), in either of the two styles the driver's
//!   files use: one flow mapping per laser (`- {laser_id: 0, rot_correction: ...}`) or block
//!   mappings (`- laser_id: 0` with the keys indented below); read with `serde_norway`, the
//!   driver's other keys ignored.
//! - `.json`: Ouster sensor metadata: `beam_altitude_angles` and `beam_azimuth_angles` (degrees; at
//!   the top level or under `beam_intrinsics`), columns from `lidar_mode` (`"1024x10"`; at the top
//!   level or under `config_params`). Ouster's radial `lidar_origin_to_beam_origin_mm` moves a point
//!   along its beam, not across rows or columns, and is not needed to order a cloud.
//! - `.csv`: Hesai's angle-correction file: a header `Laser id,Elevation,Azimuth` (or
//!   `Channel,Elevation,Azimuth`), then one line per laser, ids 1 ..= N each once, angles in
//!   degrees. Hesai's azimuth is positive clockwise (seen from above), so a laser's
//!   `azimuth_offset_deg` (left positive) is minus the file's `Azimuth`. Refused, naming the file,
//!   the line and the field: a missing or repeated laser id, a NaN or infinite angle, a line
//!   without three values.
//!
//! Refused, naming the file: no lasers or more than 65535, a laser count other than the expected
//! one (a rig's or an organized cloud's rows), non-finite or out-of-range angles (elevations within
//! +-90 degrees, azimuth offsets within +-180), two lasers at one elevation, duplicate or missing
//! velodyne `laser_id`s.

use std::path::{Path, PathBuf};

use super::beam_table::BeamTable;

/// Errors of calibration files: each names the file.
#[derive(Debug, thiserror::Error, PartialEq)]
#[error("calibration file `{path}`: {message}")]
pub struct CalibrationError {
    /// The file.
    pub path: PathBuf,
    /// What is wrong.
    pub message: String,
}

/// One laser of a calibration.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LaserCalibration {
    /// Elevation, degrees (up positive).
    pub elevation_deg: f64,
    /// Azimuth offset from the encoder angle, degrees (left positive).
    #[serde(default)]
    pub azimuth_offset_deg: f64,
    /// Beam origin left of the beam, metres.
    #[serde(default)]
    pub horizontal_offset_m: f64,
    /// Beam origin above the sensor origin, metres.
    #[serde(default)]
    pub vertical_offset_m: f64,
}

/// A sensor's calibration: its lasers in the file's order (laser id order for velodyne files).
#[derive(Clone, Debug, Default, PartialEq, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Calibration {
    /// Columns per turn, where the file says.
    #[serde(default)]
    pub columns: Option<usize>,
    /// The lasers.
    pub lasers: Vec<LaserCalibration>,
}

impl Calibration {
    /// Reads and checks a calibration file (formats in the module docs); `expected_lasers`, when
    /// given, must equal the file's laser count.
    pub fn load(path: &Path, expected_lasers: Option<usize>) -> Result<Self, CalibrationError> {
        let text = std::fs::read_to_string(path).map_err(|e| err(path, format!("cannot read: {e}")))?;
        Self::parse(path, &text, expected_lasers)
    }

    /// Parses calibration `text` (from `path`, whose extension picks the format).
    pub fn parse(path: &Path, text: &str, expected_lasers: Option<usize>) -> Result<Self, CalibrationError> {
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
        let cal = match ext.as_str() {
            "toml" => toml::from_str::<Calibration>(text).map_err(|e| err(path, e.to_string()))?,
            "txt" => parse_text(path, text)?,
            "yaml" | "yml" => parse_velodyne_yaml(path, text)?,
            "json" => parse_ouster_json(path, text)?,
            "csv" => parse_hesai_csv(path, text)?,
            other => {
                return Err(err(
                    path,
                    format!("unknown extension `{other}` (allowed: toml, txt, yaml, yml, json, csv)"),
                ));
            }
        };
        cal.check(path, expected_lasers)?;
        Ok(cal)
    }

    fn check(&self, path: &Path, expected: Option<usize>) -> Result<(), CalibrationError> {
        let n = self.lasers.len();
        if !(2..=u16::MAX as usize).contains(&n) {
            return Err(err(path, format!("{n} lasers; needs 2 ..= 65535")));
        }
        if let Some(e) = expected
            && e != n
        {
            return Err(err(path, format!("{n} lasers, but the sensor has {e}")));
        }
        if let Some(c) = self.columns
            && !(2..=1 << 20).contains(&c)
        {
            return Err(err(path, format!("columns {c}; allowed 2 ..= 1048576")));
        }
        for (i, l) in self.lasers.iter().enumerate() {
            let fields = [
                ("elevation", l.elevation_deg, 90.0),
                ("azimuth offset", l.azimuth_offset_deg, 180.0),
                ("horizontal offset", l.horizontal_offset_m, 10.0),
                ("vertical offset", l.vertical_offset_m, 10.0),
            ];
            for (name, v, limit) in fields {
                if !v.is_finite() || v.abs() > limit {
                    return Err(err(path, format!("laser {i}: {name} {v} is not finite or beyond +-{limit}")));
                }
            }
        }
        let mut e: Vec<f64> = self.lasers.iter().map(|l| l.elevation_deg).collect();
        e.sort_by(f64::total_cmp);
        if let Some(w) = e.windows(2).find(|w| w[0] == w[1]) {
            return Err(err(path, format!("two lasers at elevation {} degrees", w[0])));
        }
        Ok(())
    }

    /// The beam table of this calibration with `cols` columns over a full turn (column 0 just right
    /// of +pi, as `sim` grids).
    pub fn to_table(&self, cols: usize) -> BeamTable {
        let mut t =
            BeamTable::spinning(self.lasers.iter().map(|l| (l.elevation_deg as f32).to_radians()).collect(), cols);
        t.azimuth_offsets_rad = self.lasers.iter().map(|l| (l.azimuth_offset_deg as f32).to_radians()).collect();
        t.horizontal_offsets_m = self.lasers.iter().map(|l| l.horizontal_offset_m as f32).collect();
        t.vertical_offsets_m = self.lasers.iter().map(|l| l.vertical_offset_m as f32).collect();
        t
    }
}

fn err(path: &Path, message: impl Into<String>) -> CalibrationError {
    CalibrationError { path: path.to_path_buf(), message: message.into() }
}

fn number(path: &Path, what: &str, s: &str) -> Result<f64, CalibrationError> {
    s.trim().parse::<f64>().map_err(|_| err(path, format!("{what}: `{}` is not a number", s.trim())))
}

fn parse_text(path: &Path, text: &str) -> Result<Calibration, CalibrationError> {
    let mut lasers = Vec::new();
    for (k, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let words: Vec<&str> = line.split_whitespace().collect();
        if words.len() > 2 {
            return Err(err(path, format!("line {}: expected `elevation_deg [azimuth_offset_deg]`", k + 1)));
        }
        let what = format!("line {}", k + 1);
        let elevation_deg = number(path, &what, words[0])?;
        let azimuth_offset_deg = words.get(1).map(|w| number(path, &what, w)).transpose()?.unwrap_or(0.0);
        lasers.push(LaserCalibration { elevation_deg, azimuth_offset_deg, ..Default::default() });
    }
    Ok(Calibration { columns: None, lasers })
}

/// One laser of the velodyne driver's calibration YAML (the driver's other keys are ignored).
#[derive(serde::Deserialize)]
struct VelodyneLaser {
    laser_id: usize,
    /// Elevation, radians.
    vert_correction: f64,
    /// Azimuth offset, radians.
    #[serde(default)]
    rot_correction: f64,
    /// Metres.
    #[serde(default)]
    horiz_offset_correction: f64,
    /// Metres.
    #[serde(default)]
    vert_offset_correction: f64,
}

/// The velodyne driver's calibration YAML: `lasers:` (and optionally `num_lasers:`).
#[derive(serde::Deserialize)]
struct VelodyneCalibration {
    lasers: Vec<VelodyneLaser>,
    num_lasers: Option<usize>,
}

/// The velodyne driver's calibration YAML (module docs), read with `serde_norway` (a maintained
/// YAML parser), flow and block style alike.
fn parse_velodyne_yaml(path: &Path, text: &str) -> Result<Calibration, CalibrationError> {
    let file: VelodyneCalibration =
        serde_norway::from_str(text).map_err(|e| err(path, format!("velodyne YAML: {e}")))?;
    if file.lasers.is_empty() {
        return Err(err(path, "no `lasers:` list"));
    }
    let n = file.lasers.len();
    let mut by_id: Vec<Option<LaserCalibration>> = vec![None; n];
    for (i, l) in file.lasers.iter().enumerate() {
        if l.laser_id >= n || by_id[l.laser_id].is_some() {
            return Err(err(path, format!("laser {i}: laser_id {} repeated or beyond the {n} lasers", l.laser_id)));
        }
        let values = [l.vert_correction, l.rot_correction, l.horiz_offset_correction, l.vert_offset_correction];
        if values.iter().any(|v| !v.is_finite()) {
            return Err(err(path, format!("laser {i}: non-finite correction")));
        }
        by_id[l.laser_id] = Some(LaserCalibration {
            elevation_deg: l.vert_correction.to_degrees(),
            azimuth_offset_deg: l.rot_correction.to_degrees(),
            horizontal_offset_m: l.horiz_offset_correction,
            vertical_offset_m: l.vert_offset_correction,
        });
    }
    if let Some(count) = file.num_lasers
        && count != n
    {
        return Err(err(path, format!("num_lasers {count} but {n} lasers listed")));
    }
    Ok(Calibration { columns: None, lasers: by_id.into_iter().flatten().collect() })
}

/// Ouster sensor metadata JSON (module docs).
fn parse_ouster_json(path: &Path, text: &str) -> Result<Calibration, CalibrationError> {
    let v: serde_json::Value = serde_json::from_str(text).map_err(|e| err(path, format!("not JSON: {e}")))?;
    let find = |key: &str, parent: &str| v.get(key).or_else(|| v.get(parent).and_then(|p| p.get(key)));
    let angles = |key: &str| -> Result<Vec<f64>, CalibrationError> {
        let a = find(key, "beam_intrinsics")
            .and_then(|a| a.as_array())
            .ok_or_else(|| err(path, format!("no `{key}` array")))?;
        a.iter()
            .enumerate()
            .map(|(i, x)| x.as_f64().ok_or_else(|| err(path, format!("`{key}`[{i}] is not a number"))))
            .collect()
    };
    let alt = angles("beam_altitude_angles")?;
    let az = angles("beam_azimuth_angles")?;
    if alt.len() != az.len() {
        return Err(err(path, format!("{} altitude angles but {} azimuth angles", alt.len(), az.len())));
    }
    let columns = find("lidar_mode", "config_params")
        .and_then(|m| m.as_str())
        .and_then(|m| m.split('x').next())
        .and_then(|c| c.parse::<usize>().ok());
    Ok(Calibration {
        columns,
        lasers: alt
            .iter()
            .zip(&az)
            .map(|(&e, &a)| LaserCalibration { elevation_deg: e, azimuth_offset_deg: a, ..Default::default() })
            .collect(),
    })
}

/// Hesai's angle-correction CSV (module docs): `Laser id,Elevation,Azimuth` lines after a header.
fn parse_hesai_csv(path: &Path, text: &str) -> Result<Calibration, CalibrationError> {
    // (line number, laser id, elevation, azimuth) in file order.
    let mut rows: Vec<(usize, u32, f64, f64)> = Vec::new();
    let mut id_field = "Laser id";
    let mut header_seen = false;
    for (k, line) in text.lines().enumerate() {
        let line_no = k + 1;
        let line = line.trim().trim_start_matches('\u{feff}');
        if line.is_empty() {
            continue;
        }
        let mut cells: Vec<&str> = line.split(',').map(str::trim).collect();
        if cells.len() == 4 && cells[3].is_empty() {
            cells.pop(); // a trailing comma
        }
        if !header_seen && rows.is_empty() {
            let names: Vec<String> = cells.iter().map(|c| c.to_ascii_lowercase()).collect();
            if names.len() == 3
                && (names[0] == "laser id" || names[0] == "channel")
                && names[1] == "elevation"
                && names[2] == "azimuth"
            {
                header_seen = true;
                id_field = if names[0] == "channel" { "Channel" } else { "Laser id" };
                continue;
            }
            return Err(err(
                path,
                format!(
                    "line {line_no}: expected the header `Laser id,Elevation,Azimuth` (or `Channel,...`), found `{line}`"
                ),
            ));
        }
        if cells.len() != 3 {
            return Err(err(
                path,
                format!("line {line_no}: expected 3 values `{id_field},Elevation,Azimuth`, found {}", cells.len()),
            ));
        }
        let id = cells[0].parse::<u32>().map_err(|_| {
            err(path, format!("line {line_no}: `{id_field}` `{}` is not a whole number >= 1", cells[0]))
        })?;
        let angle = |name: &str, cell: &str| -> Result<f64, CalibrationError> {
            let v = number(path, &format!("line {line_no}: `{name}`"), cell)?;
            if v.is_finite() {
                Ok(v)
            } else {
                Err(err(path, format!("line {line_no}: `{name}` is {v}, not a finite angle")))
            }
        };
        let elevation = angle("Elevation", cells[1])?;
        let azimuth = angle("Azimuth", cells[2])?;
        rows.push((line_no, id, elevation, azimuth));
    }
    if rows.is_empty() {
        return Err(err(path, "no lasers after the header"));
    }
    let mut line_of_id: std::collections::BTreeMap<u32, usize> = std::collections::BTreeMap::new();
    for &(line_no, id, _, _) in &rows {
        if id == 0 {
            return Err(err(path, format!("line {line_no}: `{id_field}` 0; ids run from 1")));
        }
        if let Some(first) = line_of_id.insert(id, line_no) {
            return Err(err(path, format!("line {line_no}: `{id_field}` {id} repeated (first on line {first})")));
        }
    }
    // Distinct ids >= 1, sorted: the first id that is not its rank + 1 shows the missing one.
    if let Some((rank, _)) = line_of_id.keys().enumerate().find(|&(rank, &id)| id as usize != rank + 1) {
        let n = rows.len();
        return Err(err(path, format!("`{id_field}` {} missing (ids must run 1 ..= {n} without gaps)", rank + 1)));
    }
    rows.sort_by_key(|r| r.1);
    Ok(Calibration {
        columns: None,
        lasers: rows
            .iter()
            .map(|&(_, _, elevation_deg, azimuth)| LaserCalibration {
                elevation_deg,
                azimuth_offset_deg: -azimuth,
                ..Default::default()
            })
            .collect(),
    })
}
