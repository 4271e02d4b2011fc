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
use sim::scene::semantic_kitti::{CLASSES, LEARNING};

use super::config::Split;

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
