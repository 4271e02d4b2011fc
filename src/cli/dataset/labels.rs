//! The label config `DIR/groundtruth.yaml`, in the format of SemanticKITTI's `semantic-kitti.yaml`
//! (`labels`, `color_map` in BGR, `content`, `learning_map`, `learning_map_inv`, `learning_ignore`,
//! `split`), so the SemanticKITTI API (`visualize.py`, `content.py`, `evaluate_semantics.py
//! --datacfg`) and its data loaders read our datasets.
//!
//! It lists every class our scenes make (`sim::SemanticClass`), with SemanticKITTI's names and
//! learning classes (19 classes; 0 = ignored). Our bush class 73 is listed too (learning class 15,
//! vegetation), although the `.label` files hold 70 for it, as SemanticKITTI counts bushes as
//! vegetation. Lane markings go to road (as SemanticKITTI's config does); other-structure and
//! other-object are ignored (0), as there.

use sim::SemanticClass;

use super::config::Split;

/// Our classes (SemanticKITTI ids, plus bush 73) and their SemanticKITTI learning class.
pub const CLASSES: [(u16, u8); 20] = [
    (0, 0),
    (10, 1),
    (18, 4),
    (20, 5),
    (30, 6),
    (40, 9),
    (44, 10),
    (48, 11),
    (49, 12),
    (50, 13),
    (51, 14),
    (52, 0),
    (60, 9),
    (70, 15),
    (71, 16),
    (72, 17),
    (73, 15),
    (80, 18),
    (81, 19),
    (99, 0),
];

/// SemanticKITTI's learning classes and the label id each stands for (`learning_map_inv`).
pub const LEARNING: [(u8, u16, &str); 20] = [
    (0, 0, "unlabeled"),
    (1, 10, "car"),
    (2, 11, "bicycle"),
    (3, 15, "motorcycle"),
    (4, 18, "truck"),
    (5, 20, "other-vehicle"),
    (6, 30, "person"),
    (7, 31, "bicyclist"),
    (8, 32, "motorcyclist"),
    (9, 40, "road"),
    (10, 44, "parking"),
    (11, 48, "sidewalk"),
    (12, 49, "other-ground"),
    (13, 50, "building"),
    (14, 51, "fence"),
    (15, 70, "vegetation"),
    (16, 71, "trunk"),
    (17, 72, "terrain"),
    (18, 80, "pole"),
    (19, 81, "traffic-sign"),
];

/// The YAML text of the label config with `split`.
pub fn yaml(split: &Split) -> String {
    let mut y = String::from(
        "# Label config of a groundtruth dataset, in the format of SemanticKITTI's semantic-kitti.yaml.\n\
         # The .label files hold SemanticKITTI ids (bushes, our class 73, are written as 70 vegetation).\n\
         name: \"groundtruth\"\nlabels:\n",
    );
    for (id, _) in CLASSES {
        y += &format!("  {id}: \"{}\"\n", SemanticClass(id).name());
    }
    y += "color_map: # bgr\n";
    for (id, _) in CLASSES {
        let [r, g, b] = SemanticClass(id).color();
        y += &format!("  {id}: [{b}, {g}, {r}]\n");
    }
    y += "content: # not measured here: `groundtruth dataset verify` prints the class shares\n";
    for (id, _) in CLASSES {
        y += &format!("  {id}: 0.0\n");
    }
    y += "learning_map:\n";
    for (id, learn) in CLASSES {
        y += &format!("  {id}: {learn}     # \"{}\"\n", SemanticClass(id).name());
    }
    y += "learning_map_inv: # inverse of previous map\n";
    for (learn, id, name) in LEARNING {
        y += &format!("  {learn}: {id}     # \"{name}\"\n");
    }
    y += "learning_ignore: # Ignore classes\n";
    for (learn, _, name) in LEARNING {
        y += &format!("  {learn}: {}     # \"{name}\"\n", if learn == 0 { "True" } else { "False" });
    }
    let list = |v: &[u32]| v.iter().map(u32::to_string).collect::<Vec<_>>().join(", ");
    y += &format!(
        "split: # sequence numbers\n  train: [{}]\n  valid: [{}]\n  test: [{}]\n",
        list(&split.train),
        list(&split.valid),
        list(&split.test)
    );
    y
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_config_parses_as_yaml_with_every_map() {
        let split = Split { train: vec![0, 1], valid: vec![2], test: vec![] };
        let v: serde_norway::Value = serde_norway::from_str(&yaml(&split)).unwrap();
        for key in ["labels", "color_map", "content", "learning_map", "learning_map_inv", "learning_ignore", "split"] {
            assert!(v.get(key).is_some(), "no `{key}`");
        }
        assert_eq!(v["labels"][73].as_str(), Some("bush"));
        assert_eq!(v["labels"][40].as_str(), Some("road"));
        assert_eq!(v["learning_map"][73].as_u64(), Some(15));
        assert_eq!(v["learning_map"][60].as_u64(), Some(9));
        assert_eq!(v["learning_map_inv"][15].as_u64(), Some(70));
        assert_eq!(v["learning_ignore"][0].as_bool(), Some(true));
        assert_eq!(v["learning_ignore"][9].as_bool(), Some(false));
        let [r, g, b] = SemanticClass::ROAD.color();
        let bgr: Vec<u64> = v["color_map"][40].as_sequence().unwrap().iter().filter_map(|x| x.as_u64()).collect();
        assert_eq!(bgr, vec![u64::from(b), u64::from(g), u64::from(r)]);
        assert_eq!(v["split"]["train"].as_sequence().map(Vec::len), Some(2));
        assert_eq!(v["split"]["test"].as_sequence().map(Vec::len), Some(0));
        // Every class maps to a learning class that exists, and each learning class but 0 maps back
        // to a label id that maps to it.
        for (_, learn) in CLASSES {
            assert!(LEARNING.iter().any(|l| l.0 == learn));
        }
        for (learn, id, _) in LEARNING.iter().skip(1) {
            if let Some(c) = CLASSES.iter().find(|c| c.0 == *id) {
                assert_eq!(c.1, *learn, "label {id}");
            }
        }
    }
}
