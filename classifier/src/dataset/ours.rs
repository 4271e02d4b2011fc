//! Datasets written by `groundtruth dataset`: each sequence's rig and mount, read from the
//! dataset's `manifest.json`, so that every sequence is ordered with its own beam table and its
//! points moved into its vehicle frame, as it was scanned.

use std::collections::BTreeMap;
use std::path::Path;

use super::DatasetError;
use crate::ordering::SensorSetup;

/// The `format` of a dataset manifest of ours.
pub const MANIFEST_FORMAT: &str = "groundtruth SemanticKITTI-layout dataset";

/// Each sequence's sensor setup (by folder name, `00`..`99`) of the dataset in `dir`, from its
/// `manifest.json` (the rig by name or file, and the mount overrides of the sequence); `None` when
/// `dir` holds no manifest of ours (a recording of someone else's). Sequences of multi-sensor rigs
/// (points in the vehicle frame, no single beam table) are left out: they take the default setup.
pub fn sequence_setups(dir: &Path) -> Result<Option<BTreeMap<String, SensorSetup>>, DatasetError> {
    let path = dir.join("manifest.json");
    let Ok(text) = std::fs::read_to_string(&path) else { return Ok(None) };
    let invalid =
        |allowed: String| DatasetError::Invalid { flag: "manifest.json", value: path.display().to_string(), allowed };
    let m: serde_json::Value = serde_json::from_str(&text).map_err(|e| invalid(format!("valid JSON ({e})")))?;
    if m.get("format").and_then(|f| f.as_str()) != Some(MANIFEST_FORMAT) {
        return Ok(None);
    }
    // Each sequence's mounts as scanned (manifests since scan specs; any override mode applied).
    let scanned_mounts = |id: u64| -> Option<Vec<sim::rig::Mount>> {
        let entry = m["sequences"].as_array()?.iter().find(|e| e["id"].as_u64() == Some(id))?;
        serde_json::from_value(entry.get("mounts")?.clone()).ok()
    };
    let mut out = BTreeMap::new();
    for s in m["config"]["sequences"].as_array().into_iter().flatten() {
        let (Some(id), Some(rig)) = (s["id"].as_u64(), s["rig"].as_str()) else {
            return Err(invalid("sequences with an `id` and a `rig`".to_string()));
        };
        let mut r = sim::Rig::load(rig).map_err(|e| invalid(format!("a loadable rig for sequence {id} ({e})")))?;
        if r.sensors.len() != 1 {
            continue;
        }
        if let Some(mounts) = scanned_mounts(id) {
            let [mount] = mounts.as_slice() else {
                return Err(invalid(format!("sequence {id}: one mount per sensor of its rig")));
            };
            r.sensors[0].mount = *mount;
        } else if let Some(mount) = s.get("mount").and_then(|m| m.as_object()) {
            let m = &mut r.sensors[0].mount;
            for (field, slot, limit) in [
                ("x_m", &mut m.x_m, 100.0),
                ("y_m", &mut m.y_m, 100.0),
                ("z_m", &mut m.z_m, 100.0),
                ("roll_deg", &mut m.roll_deg, 180.0),
                ("pitch_deg", &mut m.pitch_deg, 180.0),
                ("yaw_deg", &mut m.yaw_deg, 180.0),
            ] {
                if let Some(v) = mount.get(field).and_then(|v| v.as_f64()) {
                    if !(v.is_finite() && v.abs() <= limit) {
                        return Err(invalid(format!(
                            "sequence {id}: mount.{field} = {v}, allowed -{limit} ..= {limit}"
                        )));
                    }
                    *slot = v as f32;
                }
            }
        }
        let setup =
            SensorSetup::new(Some(&r), None).map_err(|source| DatasetError::Classify { path: path.clone(), source })?;
        out.insert(format!("{id:02}"), setup);
    }
    Ok(Some(out))
}
