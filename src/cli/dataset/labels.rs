//! The label config `DIR/groundtruth.yaml`, in the format of SemanticKITTI's `semantic-kitti.yaml`
//! (`labels`, `color_map` in BGR, `content`, `learning_map`, `learning_map_inv`, `learning_ignore`,
//! `split`), so the SemanticKITTI API (`visualize.py`, `content.py`, `evaluate_semantics.py
//! --datacfg`) and its data loaders read our datasets.
//!
//! It lists every SemanticKITTI label id (our classes, `sim::SemanticClass`, use the same ids) with
//! SemanticKITTI's names, colours and learning classes (19 classes; 0 = ignored), so the evaluation
//! scripts, which name every learning class, run on it (tested with `content.py` and
//! `evaluate_semantics.py`). Our bush class 73 is listed too (learning class 15, vegetation),
//! although the `.label` files hold 70 for it, as SemanticKITTI counts bushes as vegetation. Lane
//! markings go to road and other-structure and other-object are ignored (0), as in SemanticKITTI.

use sim::SemanticClass;

use super::config::Split;

/// Every SemanticKITTI label id (our classes use the same ids) with its name, BGR colour and
/// learning class, as SemanticKITTI's `semantic-kitti.yaml` has them, plus our bush class 73
/// (learning class 15, vegetation; its colour [`SemanticClass::BUSH`]'s). The ids our scenes do not
/// make (bicycle, bus, moving-*, ...) are listed too: the evaluation scripts name every learning
/// class through `labels[learning_map_inv[c]]`.
pub const CLASSES: [(u16, &str, [u8; 3], u8); 35] = [
    (0, "unlabeled", [0, 0, 0], 0),
    (1, "outlier", [0, 0, 255], 0),
    (10, "car", [245, 150, 100], 1),
    (11, "bicycle", [245, 230, 100], 2),
    (13, "bus", [250, 80, 100], 5),
    (15, "motorcycle", [150, 60, 30], 3),
    (16, "on-rails", [255, 0, 0], 5),
    (18, "truck", [180, 30, 80], 4),
    (20, "other-vehicle", [255, 0, 0], 5),
    (30, "person", [30, 30, 255], 6),
    (31, "bicyclist", [200, 40, 255], 7),
    (32, "motorcyclist", [90, 30, 150], 8),
    (40, "road", [255, 0, 255], 9),
    (44, "parking", [255, 150, 255], 10),
    (48, "sidewalk", [75, 0, 75], 11),
    (49, "other-ground", [75, 0, 175], 12),
    (50, "building", [0, 200, 255], 13),
    (51, "fence", [50, 120, 255], 14),
    (52, "other-structure", [0, 150, 255], 0),
    (60, "lane-marking", [170, 255, 150], 9),
    (70, "vegetation", [0, 175, 0], 15),
    (71, "trunk", [0, 60, 135], 16),
    (72, "terrain", [80, 240, 150], 17),
    (73, "bush", [0, 0, 0], 15),
    (80, "pole", [150, 240, 255], 18),
    (81, "traffic-sign", [0, 0, 255], 19),
    (99, "other-object", [255, 255, 50], 0),
    (252, "moving-car", [245, 150, 100], 1),
    (253, "moving-bicyclist", [200, 40, 255], 7),
    (254, "moving-person", [30, 30, 255], 6),
    (255, "moving-motorcyclist", [90, 30, 150], 8),
    (256, "moving-on-rails", [255, 0, 0], 5),
    (257, "moving-bus", [250, 80, 100], 5),
    (258, "moving-truck", [180, 30, 80], 4),
    (259, "moving-other-vehicle", [255, 0, 0], 5),
];

/// SemanticKITTI's learning classes and the label id each stands for (`learning_map_inv`).
pub const LEARNING: [(u8, u16); 20] = [
    (0, 0),
    (1, 10),
    (2, 11),
    (3, 15),
    (4, 18),
    (5, 20),
    (6, 30),
    (7, 31),
    (8, 32),
    (9, 40),
    (10, 44),
    (11, 48),
    (12, 49),
    (13, 50),
    (14, 51),
    (15, 70),
    (16, 71),
    (17, 72),
    (18, 80),
    (19, 81),
];

/// BGR colour of a class of the table (bush: ours).
fn bgr(id: u16, table: [u8; 3]) -> [u8; 3] {
    if id == SemanticClass::BUSH.0 {
        let [r, g, b] = SemanticClass::BUSH.color();
        [b, g, r]
    } else {
        table
    }
}

/// The name of a class of the table.
fn name(id: u16) -> &'static str {
    CLASSES.iter().find(|c| c.0 == id).map_or("unlabeled", |c| c.1)
}

/// The YAML text of the label config with `split`.
pub fn yaml(split: &Split) -> String {
    let mut y = String::from(
        "# Label config of a groundtruth dataset, in the format of SemanticKITTI's semantic-kitti.yaml.\n\
         # The .label files hold SemanticKITTI ids (bushes, our class 73, are written as 70 vegetation).\n\
         name: \"groundtruth\"\nlabels:\n",
    );
    for (id, name, _, _) in CLASSES {
        y += &format!("  {id}: \"{name}\"\n");
    }
    y += "color_map: # bgr\n";
    for (id, _, color, _) in CLASSES {
        let [b, g, r] = bgr(id, color);
        y += &format!("  {id}: [{b}, {g}, {r}]\n");
    }
    y += "content: # not measured here: `groundtruth dataset verify` prints the class shares\n";
    for (id, _, _, _) in CLASSES {
        y += &format!("  {id}: 0.0\n");
    }
    y += "learning_map:\n";
    for (id, name, _, learn) in CLASSES {
        y += &format!("  {id}: {learn}     # \"{name}\"\n");
    }
    y += "learning_map_inv: # inverse of previous map\n";
    for (learn, id) in LEARNING {
        y += &format!("  {learn}: {id}     # \"{}\"\n", name(id));
    }
    y += "learning_ignore: # Ignore classes\n";
    for (learn, id) in LEARNING {
        y += &format!("  {learn}: {}     # \"{}\"\n", if learn == 0 { "True" } else { "False" }, name(id));
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
        let bgr: Vec<u64> = v["color_map"][10].as_sequence().unwrap().iter().filter_map(|x| x.as_u64()).collect();
        assert_eq!(bgr, vec![245, 150, 100]);
        assert_eq!(v["split"]["train"].as_sequence().map(Vec::len), Some(2));
        assert_eq!(v["split"]["test"].as_sequence().map(Vec::len), Some(0));
        // Every class maps to a learning class that exists, and each learning class but 0 maps back
        // to a label id that maps to it.
        for (id, _, _, learn) in CLASSES {
            assert!(LEARNING.iter().any(|l| l.0 == learn), "label {id}");
        }
        for (learn, id) in LEARNING {
            let c = CLASSES.iter().find(|c| c.0 == id).expect("listed");
            assert_eq!(c.3, learn, "label {id}");
        }
        // Every class our scenes make is listed under its own name.
        for id in [0u16, 10, 18, 20, 30, 40, 44, 48, 49, 50, 51, 52, 60, 70, 71, 72, 73, 80, 81, 99] {
            assert_eq!(v["labels"][id as usize].as_str(), Some(SemanticClass(id).name()), "label {id}");
        }
    }
}
