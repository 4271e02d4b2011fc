//! The one mount override: which part of the rig moves (one sensor, by index or name, or the whole
//! rig as one body), whether the values replace the mount or are added to it, and the values, each
//! checked against the one set of limits ([`MOUNT_LIMITS`]) that every front end shares.

use glam::{EulerRot, Quat, Vec3};
use serde::{Deserialize, Serialize};
use sim::rig::Mount;

use crate::error::{Result, ScenarioError};

/// The allowed range of each override value: `(field, low, high)`. Positions (metres) as far as a
/// rig file's mounts may be (`sim::rig::MAX_MOUNT_OFFSET_M`, 100 m: a sensor on a mast or a test
/// pole), angles (degrees) one turn either way (as a rig file's). The union of the limits the
/// scenario builder (x, y +-50 m, z -5 ..= 20 m, pitch +-90 deg) and dataset files (+-100 m,
/// +-180 deg) had before they were one type: nothing either accepted is refused.
pub const MOUNT_LIMITS: [(&str, f32, f32); 6] = [
    ("x_m", -100.0, 100.0),
    ("y_m", -100.0, 100.0),
    ("z_m", -100.0, 100.0),
    ("roll_deg", -360.0, 360.0),
    ("pitch_deg", -360.0, 360.0),
    ("yaw_deg", -360.0, 360.0),
];

/// The name that [`MountTarget`] gives the whole rig.
pub const WHOLE_RIG: &str = "rig";

/// What a mount override moves.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum MountTarget {
    /// The sensor at this index of the rig's `sensors`.
    Index(usize),
    /// The sensor of this name, or `"rig"`: the whole rig as one rigid body.
    Name(String),
}

impl MountTarget {
    /// The whole rig as one body.
    pub fn rig() -> Self {
        Self::Name(WHOLE_RIG.to_string())
    }

    /// Whether this is the whole rig.
    pub fn is_rig(&self) -> bool {
        matches!(self, Self::Name(n) if n == WHOLE_RIG)
    }
}

/// How the override's values apply.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MountMode {
    /// The values replace the mount's (the default).
    #[default]
    Absolute,
    /// The values are added to the rig's own mount.
    Relative,
}

/// Overrides of a mount; a `None` value keeps the rig's.
///
/// - a sensor (`sensor = 0` or `sensor = "roof_3"`; left out: the rig's only sensor, refused for a
///   rig of several): `absolute` values replace that sensor's mount fields, `relative` ones are
///   added to them;
/// - `sensor = "rig"`: the whole rig moves as one rigid body. Its reference point is the mean of
///   the sensors' positions; `x_m y_m z_m` place that point (`absolute`, vehicle frame) or shift it
///   (`relative`); `roll_deg pitch_deg yaw_deg` turn the body about it from the rig as designed in
///   either mode (the body's design attitude is zero; + pitch tilts every sensor down), so the
///   sensors keep their relative poses.
///
/// Every value is checked against [`MOUNT_LIMITS`], the mount that results against the rig file's.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MountOverride {
    /// What moves (default: the rig's only sensor).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sensor: Option<MountTarget>,
    /// `absolute` (default) or `relative` to the rig's own mount.
    #[serde(default)]
    pub mode: MountMode,
    /// Position x (forward), metres.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub x_m: Option<f32>,
    /// Position y (left), metres.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub y_m: Option<f32>,
    /// Position z (up, above the ground under the rear axle), metres.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub z_m: Option<f32>,
    /// Roll, degrees.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub roll_deg: Option<f32>,
    /// Pitch, degrees; + tilts the sensor down.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pitch_deg: Option<f32>,
    /// Yaw, degrees; + turns it left.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub yaw_deg: Option<f32>,
}

impl MountOverride {
    /// The six values in [`MOUNT_LIMITS`] order.
    pub fn values(&self) -> [Option<f32>; 6] {
        [self.x_m, self.y_m, self.z_m, self.roll_deg, self.pitch_deg, self.yaw_deg]
    }

    /// Whether no value is set.
    pub fn is_empty(&self) -> bool {
        self.values().iter().all(Option::is_none)
    }

    /// Checks every set value against [`MOUNT_LIMITS`], naming `mount.<field>` and its range.
    ///
    /// ```
    /// let o = groundtruth_scenario::MountOverride { z_m: Some(150.0), ..Default::default() };
    /// assert_eq!(o.validate().unwrap_err().to_string(), "invalid value for `mount.z_m`: 150 (allowed: -100 ..= 100)");
    /// ```
    pub fn validate(&self) -> Result<()> {
        for ((name, lo, hi), v) in MOUNT_LIMITS.iter().zip(self.values()) {
            if let Some(v) = v
                && !(v.is_finite() && (*lo..=*hi).contains(&v))
            {
                return Err(ScenarioError::invalid(format!("mount.{name}"), v, format!("{lo} ..= {hi}")));
            }
        }
        Ok(())
    }

    /// Sets the fields `other` sets (its target and mode too, when it names them).
    pub fn merge(&mut self, other: &MountOverride) {
        if other.sensor.is_some() {
            self.sensor.clone_from(&other.sensor);
        }
        if other.mode != MountMode::Absolute {
            self.mode = other.mode;
        }
        self.x_m = other.x_m.or(self.x_m);
        self.y_m = other.y_m.or(self.y_m);
        self.z_m = other.z_m.or(self.z_m);
        self.roll_deg = other.roll_deg.or(self.roll_deg);
        self.pitch_deg = other.pitch_deg.or(self.pitch_deg);
        self.yaw_deg = other.yaw_deg.or(self.yaw_deg);
    }

    /// `mount` with the set fields replaced (`absolute`) or added to (`relative`).
    pub fn apply(&self, mount: Mount) -> Mount {
        let set = |v: Option<f32>, old: f32| match (v, self.mode) {
            (None, _) => old,
            (Some(v), MountMode::Absolute) => v,
            (Some(v), MountMode::Relative) => old + v,
        };
        Mount {
            x_m: set(self.x_m, mount.x_m),
            y_m: set(self.y_m, mount.y_m),
            z_m: set(self.z_m, mount.z_m),
            roll_deg: set(self.roll_deg, mount.roll_deg),
            pitch_deg: set(self.pitch_deg, mount.pitch_deg),
            yaw_deg: set(self.yaw_deg, mount.yaw_deg),
        }
    }

    /// Validates and applies the override to `rig` (see the type's doc); the rig's mounts are
    /// checked afterwards.
    pub fn apply_to_rig(&self, rig: &mut sim::Rig) -> Result<()> {
        self.validate()?;
        match &self.sensor {
            Some(t) if t.is_rig() => move_body(rig, self.values(), self.mode),
            target => {
                let i = self.sensor_index(rig, target.as_ref())?;
                rig.sensors[i].mount = self.apply(rig.sensors[i].mount);
            }
        }
        rig.validate()?;
        Ok(())
    }

    /// The index of the sensor `target` names in `rig` (`None`: its only sensor).
    fn sensor_index(&self, rig: &sim::Rig, target: Option<&MountTarget>) -> Result<usize> {
        let n = rig.sensors.len();
        let names = || rig.sensors.iter().map(|s| s.name.as_str()).collect::<Vec<_>>().join(", ");
        match target {
            None if n == 1 => Ok(0),
            None => Err(ScenarioError::invalid(
                "mount.sensor",
                "(none)",
                format!(
                    "the rig has {n} sensors: an index 0 ..= {}, a name ({}), or \"{WHOLE_RIG}\" for the whole rig",
                    n.saturating_sub(1),
                    names()
                ),
            )),
            Some(MountTarget::Index(i)) if *i < n => Ok(*i),
            Some(MountTarget::Index(i)) => Err(ScenarioError::invalid(
                "mount.sensor",
                i,
                format!("0 ..= {} (the rig's sensors), a name or \"{WHOLE_RIG}\"", n.saturating_sub(1)),
            )),
            Some(MountTarget::Name(name)) => rig.sensors.iter().position(|s| &s.name == name).ok_or_else(|| {
                ScenarioError::invalid(
                    "mount.sensor",
                    format!("`{name}`"),
                    format!("a sensor of the rig ({}), an index or \"{WHOLE_RIG}\"", names()),
                )
            }),
        }
    }
}

/// Moves the whole rig as one body (see [`MountOverride`]): `values` are x, y, z (the reference
/// point's new position, or its shift) and roll, pitch, yaw (the body's turn from the design).
fn move_body(rig: &mut sim::Rig, values: [Option<f32>; 6], mode: MountMode) {
    let n = rig.sensors.len().max(1) as f32;
    let origin =
        rig.sensors.iter().map(|s| Vec3::new(s.mount.x_m, s.mount.y_m, s.mount.z_m)).fold(Vec3::ZERO, |a, b| a + b) / n;
    let place = |v: Option<f32>, o: f32| match (v, mode) {
        (None, _) => o,
        (Some(v), MountMode::Absolute) => v,
        (Some(v), MountMode::Relative) => o + v,
    };
    let target = Vec3::new(place(values[0], origin.x), place(values[1], origin.y), place(values[2], origin.z));
    let (roll, pitch, yaw) = (values[3].unwrap_or(0.0), values[4].unwrap_or(0.0), values[5].unwrap_or(0.0));
    let turned = roll != 0.0 || pitch != 0.0 || yaw != 0.0;
    let body = Quat::from_euler(EulerRot::ZYX, yaw.to_radians(), pitch.to_radians(), roll.to_radians());
    for s in &mut rig.sensors {
        let m = &mut s.mount;
        let p = Vec3::new(m.x_m, m.y_m, m.z_m) - origin;
        let p = target + if turned { body * p } else { p };
        (m.x_m, m.y_m, m.z_m) = (p.x, p.y, p.z);
        if turned {
            let q = body
                * Quat::from_euler(
                    EulerRot::ZYX,
                    m.yaw_deg.to_radians(),
                    m.pitch_deg.to_radians(),
                    m.roll_deg.to_radians(),
                );
            let (z, y, x) = q.to_euler(EulerRot::ZYX);
            (m.yaw_deg, m.pitch_deg, m.roll_deg) = (z.to_degrees(), y.to_degrees(), x.to_degrees());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_sensor_absolute_and_relative() {
        let mut rig = sim::Rig::preset("vlp16-roof").unwrap();
        let z0 = rig.sensors[0].mount.z_m;
        let rel = MountOverride { mode: MountMode::Relative, z_m: Some(0.5), ..Default::default() };
        rel.apply_to_rig(&mut rig).unwrap();
        assert_eq!(rig.sensors[0].mount.z_m, z0 + 0.5);
        MountOverride { z_m: Some(2.5), ..Default::default() }.apply_to_rig(&mut rig).unwrap();
        assert_eq!(rig.sensors[0].mount.z_m, 2.5);
    }

    #[test]
    fn several_sensors_need_one_named() {
        let mut rig = sim::Rig::preset("lux-roof-4").unwrap();
        let o = MountOverride { z_m: Some(2.0), ..Default::default() };
        let e = o.apply_to_rig(&mut rig).unwrap_err().to_string();
        assert!(e.contains("mount.sensor") && e.contains("4 sensors"), "{e}");
        let name = rig.sensors[3].name.clone();
        let o = MountOverride { sensor: Some(MountTarget::Name(name)), ..o };
        o.apply_to_rig(&mut rig).unwrap();
        assert_eq!(rig.sensors[3].mount.z_m, 2.0);
        let o = MountOverride { sensor: Some(MountTarget::Index(7)), ..o };
        assert!(o.apply_to_rig(&mut rig).unwrap_err().to_string().contains("0 ..= 3"));
    }

    #[test]
    fn the_whole_rig_moves_as_one_body() {
        let base = sim::Rig::preset("lux-roof-4").unwrap();
        let mut rig = base.clone();
        let o = MountOverride { sensor: Some(MountTarget::rig()), z_m: Some(2.0), ..Default::default() };
        o.apply_to_rig(&mut rig).unwrap();
        let mean_z: f32 = rig.sensors.iter().map(|s| s.mount.z_m).sum::<f32>() / 4.0;
        assert!((mean_z - 2.0).abs() < 1e-5, "{mean_z}");
        // Relative: every sensor 0.3 m higher, angles untouched.
        let mut rig = base.clone();
        let o = MountOverride { mode: MountMode::Relative, z_m: Some(0.3), ..o };
        o.apply_to_rig(&mut rig).unwrap();
        for (a, b) in rig.sensors.iter().zip(&base.sensors) {
            assert!((a.mount.z_m - b.mount.z_m - 0.3).abs() < 1e-5);
            assert_eq!(a.mount.pitch_deg, b.mount.pitch_deg);
        }
    }

    #[test]
    fn limits_name_the_field_and_range() {
        for (k, (name, lo, hi)) in MOUNT_LIMITS.into_iter().enumerate() {
            let with = |v: f32| {
                let mut values = [None; 6];
                values[k] = Some(v);
                let [x_m, y_m, z_m, roll_deg, pitch_deg, yaw_deg] = values;
                MountOverride { x_m, y_m, z_m, roll_deg, pitch_deg, yaw_deg, ..Default::default() }
            };
            assert!(with(hi).validate().is_ok() && with(lo).validate().is_ok());
            let o = with(hi + 1.0);
            let e = o.validate().unwrap_err().to_string();
            assert_eq!(e, format!("invalid value for `mount.{name}`: {} (allowed: {lo} ..= {hi})", hi + 1.0));
        }
    }
}
