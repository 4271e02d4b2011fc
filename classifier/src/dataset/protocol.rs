//! Evaluation protocols: which labels are ground, which are left out of the scores.
//!
//! Changing the protocol alone moves a method's F1 by several points on SemanticKITTI
//! (url-kaist/patchwork-plusplus issues #87 and #88), so every score names its protocol:
//!
//! | name | ground truth ground | left out | as in |
//! |---|---|---|---|
//! | `semantickitti` (default) | 40 road, 44 parking, 48 sidewalk, 49 other-ground, 60 lane-marking, 72 terrain | 0 unlabeled, 1 outlier | SemanticKITTI's ground classes |
//! | `patchworkpp` | the same | 0, 1 and 70 vegetation | Patchwork++'s `evaluate_semantickitti.py --eval_protocol patchworkpp`: vegetation called ground leaves the precision's denominator |
//! | `patchwork` | the same, plus 70 vegetation lower than `0.75 x sensor height` below the sensor | 0, 1 | the original Patchwork's `count_num_ground` (`utils.hpp`), `consider_outliers = true` |
//!
//! In all of them no-returns (points at `0, 0, 0`, or not finite) are left out, everything else is
//! non-ground (moving classes, other-structure and other-object included), and the class is the
//! label's lower 16 bits. Leaving 70 out (`patchworkpp`) gives the same precision, recall, F1 and
//! IoU as Patchwork++'s script, which drops predicted-ground vegetation from the precision's
//! denominator only (vegetation called non-ground is a true negative, which none of the four
//! counts); accuracy differs. Both papers' scripts average precision, recall and F1 over frames
//! (macro, per sequence then over sequences); [`super::MethodScore`] reports pooled counts and
//! the frame means.

use std::collections::BTreeSet;

use serde::Serialize;

use super::DatasetError;

/// SemanticKITTI's ground classes: road, parking, sidewalk, other-ground, lane-marking, terrain.
pub const GROUND_CLASSES: [u16; 6] = [40, 44, 48, 49, 60, 72];

/// The classes left out by default: unlabeled, outlier.
pub const IGNORED_CLASSES: [u16; 2] = [0, 1];

/// SemanticKITTI's vegetation class.
pub const VEGETATION: u16 = 70;

/// Class ids of other public datasets in the SemanticKITTI layout that `--ground` and `--ignore`
/// take beside SemanticKITTI's own: WADS's falling snow and the snow lying on the ground.
pub const OTHER_DATASET_CLASSES: [(u16, &str); 2] = [(110, "active snowfall (WADS)"), (111, "accumulated snow (WADS)")];

/// Refuses an empty class list given to `flag`.
fn non_empty(flag: &'static str, ids: &[u32]) -> Result<(), DatasetError> {
    if ids.is_empty() {
        return Err(DatasetError::Invalid {
            flag,
            value: "(empty)".to_string(),
            allowed: "at least one class id".to_string(),
        });
    }
    Ok(())
}

/// `id` as a class id `flag` takes: a SemanticKITTI label id or one of [`OTHER_DATASET_CLASSES`].
fn class_id(flag: &'static str, id: u32) -> Result<u16, DatasetError> {
    u16::try_from(id)
        .ok()
        .filter(|&c| sim::scene::semantic_kitti::is_known(c) || OTHER_DATASET_CLASSES.iter().any(|o| o.0 == c))
        .ok_or(DatasetError::UnknownClass { flag, id })
}

/// The protocols by name.
pub const PROTOCOLS: [&str; 3] = ["semantickitti", "patchworkpp", "patchwork"];

/// What counts as ground and what is left out.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Protocol {
    /// Name (one of [`PROTOCOLS`], with `+ground` where the ground set was changed).
    pub name: String,
    /// Ground truth ground class ids.
    pub ground: BTreeSet<u16>,
    /// Class ids left out of the scores.
    pub ignored: BTreeSet<u16>,
    /// Vegetation counts as ground below this height in the sensor frame, metres (`patchwork`).
    pub low_vegetation_below_z_m: Option<f32>,
}

impl Protocol {
    /// The protocol called `name`; `sensor_height_m` is used by `patchwork` only.
    ///
    /// ```
    /// use classifier::dataset::Protocol;
    /// let p = Protocol::named("patchworkpp", 1.73)?;
    /// assert!(p.ignored.contains(&70) && p.ground.contains(&72));
    /// assert_eq!(p.truth(70, -2.0), None);     // vegetation: left out
    /// assert_eq!(p.truth(40, -1.7), Some(true));
    /// let q = Protocol::named("patchwork", 1.73)?;
    /// assert_eq!(q.truth(70, -1.5), Some(true)); // low vegetation is ground there
    /// assert_eq!(q.truth(70, -1.0), Some(false));
    /// # Ok::<(), classifier::dataset::DatasetError>(())
    /// ```
    pub fn named(name: &str, sensor_height_m: f32) -> Result<Self, DatasetError> {
        let ground: BTreeSet<u16> = GROUND_CLASSES.into_iter().collect();
        let mut ignored: BTreeSet<u16> = IGNORED_CLASSES.into_iter().collect();
        let mut low = None;
        match name {
            "semantickitti" => {}
            "patchworkpp" => {
                ignored.insert(VEGETATION);
            }
            "patchwork" => {
                if !(sensor_height_m.is_finite() && (0.0..=10.0).contains(&sensor_height_m)) {
                    return Err(DatasetError::Invalid {
                        flag: "--sensor-height",
                        value: sensor_height_m.to_string(),
                        allowed: "0 ..= 10 m".to_string(),
                    });
                }
                low = Some(-0.75 * sensor_height_m);
            }
            _ => {
                return Err(DatasetError::Invalid {
                    flag: "--protocol",
                    value: name.to_string(),
                    allowed: format!("one of {}", PROTOCOLS.join(", ")),
                });
            }
        }
        Ok(Self { name: name.to_string(), ground, ignored, low_vegetation_below_z_m: low })
    }

    /// The same protocol with another ground class set (`--ground`); every id must be a
    /// SemanticKITTI label id, and none may be ignored too.
    pub fn with_ground(mut self, ground: &[u32]) -> Result<Self, DatasetError> {
        non_empty("--ground", ground)?;
        let mut set = BTreeSet::new();
        for &id in ground {
            let class = class_id("--ground", id)?;
            if self.ignored.contains(&class) {
                return Err(DatasetError::Invalid {
                    flag: "--ground",
                    value: id.to_string(),
                    allowed: format!("a class the protocol `{}` does not leave out", self.name),
                });
            }
            set.insert(class);
        }
        if set != self.ground {
            self.name = format!("{}+ground", self.name);
            self.ground = set;
        }
        Ok(self)
    }

    /// The same protocol with more classes left out (`--ignore`; e.g. WADS's falling snow, 110, as
    /// issue 45 scores real snowfall): each a SemanticKITTI label id or one of
    /// [`OTHER_DATASET_CLASSES`], none of the ground classes.
    ///
    /// ```
    /// use classifier::dataset::Protocol;
    /// let p = Protocol::named("semantickitti", 1.73)?.with_ground(&[40, 44, 48, 49, 60, 72, 111])?.with_ignored(&[110])?;
    /// assert_eq!(p.name, "semantickitti+ground+ignore");
    /// assert_eq!((p.truth(110, -1.0), p.truth(111, -1.7)), (None, Some(true)));
    /// # Ok::<(), classifier::dataset::DatasetError>(())
    /// ```
    pub fn with_ignored(mut self, ignored: &[u32]) -> Result<Self, DatasetError> {
        non_empty("--ignore", ignored)?;
        let before = self.ignored.len();
        for &id in ignored {
            let class = class_id("--ignore", id)?;
            if self.ground.contains(&class) {
                return Err(DatasetError::Invalid {
                    flag: "--ignore",
                    value: id.to_string(),
                    allowed: "a class that is not ground (change the ground set with --ground)".to_string(),
                });
            }
            self.ignored.insert(class);
        }
        if self.ignored.len() != before {
            self.name = format!("{}+ignore", self.name);
        }
        Ok(self)
    }

    /// The truth of a point of class `class` at height `z_in_sensor_m` (sensor frame): `Some(true)`
    /// ground, `Some(false)` non-ground, `None` left out.
    pub fn truth(&self, class: u16, z_in_sensor_m: f32) -> Option<bool> {
        if self.ignored.contains(&class) {
            return None;
        }
        if self.ground.contains(&class) {
            return Some(true);
        }
        Some(class == VEGETATION && self.low_vegetation_below_z_m.is_some_and(|z| z_in_sensor_m < z))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn named_protocols_and_their_refusals() {
        let d = Protocol::named("semantickitti", 1.73).unwrap();
        assert_eq!(d.truth(0, 0.0), None);
        assert_eq!(d.truth(1, 0.0), None);
        assert_eq!(d.truth(72, 0.0), Some(true));
        assert_eq!(d.truth(70, -5.0), Some(false));
        assert_eq!(d.truth(252, 0.0), Some(false));
        let e = Protocol::named("kitti", 1.73).unwrap_err().to_string();
        assert!(e.contains("--protocol") && e.contains("patchworkpp"), "{e}");
        let e = Protocol::named("patchwork", f32::NAN).unwrap_err().to_string();
        assert!(e.contains("--sensor-height"), "{e}");
        let g = d.clone().with_ground(&[40, 44]).unwrap();
        assert_eq!(g.name, "semantickitti+ground");
        assert_eq!(g.truth(72, 0.0), Some(false));
        let same = d.clone().with_ground(&[40, 44, 48, 49, 60, 72]).unwrap();
        assert_eq!(same.name, "semantickitti");
        let e = d.clone().with_ground(&[40, 41]).unwrap_err().to_string();
        assert!(e.contains("--ground") && e.contains("41"), "{e}");
        let e = d.clone().with_ground(&[40, 70_000]).unwrap_err().to_string();
        assert!(e.contains("70000"), "{e}");
        let e = d.clone().with_ground(&[40, 0]).unwrap_err().to_string();
        assert!(e.contains("does not leave out"), "{e}");
        // WADS: falling snow left out, snow on the ground counted as ground.
        let w = d.clone().with_ground(&[40, 44, 48, 49, 60, 72, 111]).unwrap().with_ignored(&[110]).unwrap();
        assert_eq!(w.name, "semantickitti+ground+ignore");
        assert_eq!((w.truth(110, 0.0), w.truth(111, 0.0), w.truth(50, 0.0)), (None, Some(true), Some(false)));
        assert_eq!(d.clone().with_ignored(&[0, 1]).unwrap().name, "semantickitti");
        let e = d.clone().with_ignored(&[112]).unwrap_err().to_string();
        assert!(e.contains("--ignore") && e.contains("112"), "{e}");
        let e = d.clone().with_ignored(&[]).unwrap_err().to_string();
        assert!(e.contains("--ignore") && e.contains("empty"), "{e}");
        let e = d.clone().with_ignored(&[72]).unwrap_err().to_string();
        assert!(e.contains("--ignore") && e.contains("not ground"), "{e}");
        let e = d.with_ground(&[40, 110]).unwrap().with_ignored(&[110]).unwrap_err().to_string();
        assert!(e.contains("110"), "{e}");
    }
}
