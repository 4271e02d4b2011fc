//! SemanticKITTI's label table: every label id with its name, BGR colour and learning class, as
//! SemanticKITTI's `semantic-kitti.yaml` has them, plus our bush class 73. The dataset writer's
//! label config and the evaluation of labelled recordings (which class ids exist) read it.

/// Every SemanticKITTI label id (our classes use the same ids) with its name, BGR colour and
/// learning class, as SemanticKITTI's `semantic-kitti.yaml` has them, plus our bush class 73
/// (learning class 15, vegetation; its colour [`SemanticClass::BUSH`]'s) and our weather classes
/// fog 150, rain 151 and snow 152 (learning class 0, ignored, as SemanticKITTI's outliers; returns
/// from the air, [`crate::effects::weather`]). The ids our scenes do not
/// make (bicycle, bus, moving-*, ...) are listed too: the evaluation scripts name every learning
/// class through `labels[learning_map_inv[c]]`.
pub const CLASSES: [(u16, &str, [u8; 3], u8); 38] = [
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
    (150, "fog", [200, 200, 200], 0),
    (151, "rain", [255, 160, 90], 0),
    (152, "snow", [255, 250, 240], 0),
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

/// Whether `id` is a label id of the table.
///
/// ```
/// use sim::scene::semantic_kitti::is_known;
/// assert!(is_known(40) && is_known(252) && !is_known(41));
/// ```
pub fn is_known(id: u16) -> bool {
    CLASSES.iter().any(|c| c.0 == id)
}

/// The name of a label id of the table (`None` for others).
pub fn name_of(id: u16) -> Option<&'static str> {
    CLASSES.iter().find(|c| c.0 == id).map(|c| c.1)
}
