//! Semantic classes, using the SemanticKITTI label ids, plus one of our own:
//!
//! | id | name | what | SemanticKITTI `.label` | LAS (ASPRS) |
//! |----|------|------|------------------------|-------------|
//! | 70 | vegetation | tree canopy (branches and leaves) | 70 vegetation | 5 high vegetation |
//! | 71 | trunk | tree trunks | 71 trunk | 5 high vegetation |
//! | 73 | bush | bushes and shrubs (ours: seed 002 counts them apart from the canopy) | 70 vegetation | 4 medium vegetation |
//!
//! SemanticKITTI has no bush class (its "vegetation" holds canopy and bushes alike), so the id 73,
//! unused in its label config, is ours. Our own ordered formats (PCD, PLY) keep 73; the KITTI
//! `.label` writer writes [`SemanticClass::semantic_kitti_id`] (73 -> 70), so the standard
//! SemanticKITTI tools and label configs read our files, and the LAS writer writes
//! [`SemanticClass::las_class`] (bushes 4, canopy and trunks 5).

use serde::{Deserialize, Serialize};

/// A SemanticKITTI semantic label id (`u16`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize, Default)]
#[serde(transparent)]
pub struct SemanticClass(pub u16);

impl SemanticClass {
    /// No label (no return).
    pub const UNLABELED: Self = Self(0);
    /// Car.
    pub const CAR: Self = Self(10);
    /// Truck.
    pub const TRUCK: Self = Self(18);
    /// Other vehicle (vans, trailers).
    pub const OTHER_VEHICLE: Self = Self(20);
    /// Person.
    pub const PERSON: Self = Self(30);
    /// Road.
    pub const ROAD: Self = Self(40);
    /// Parking.
    pub const PARKING: Self = Self(44);
    /// Sidewalk.
    pub const SIDEWALK: Self = Self(48);
    /// Other ground.
    pub const OTHER_GROUND: Self = Self(49);
    /// Building.
    pub const BUILDING: Self = Self(50);
    /// Fence (also walls, guard rails, barriers).
    pub const FENCE: Self = Self(51);
    /// Other structure (pillars, ceilings, platforms).
    pub const OTHER_STRUCTURE: Self = Self(52);
    /// Lane marking.
    pub const LANE_MARKING: Self = Self(60);
    /// Vegetation: tree canopy, branches and leaves (SemanticKITTI's class also holds bushes; ours
    /// has [`Self::BUSH`] for those).
    pub const VEGETATION: Self = Self(70);
    /// Trunk.
    pub const TRUNK: Self = Self(71);
    /// Terrain.
    pub const TERRAIN: Self = Self(72);
    /// Bushes and shrubs (73, not a SemanticKITTI id: written as 70 vegetation to KITTI `.label`
    /// files, as 4 medium vegetation to LAS; see the module docs).
    pub const BUSH: Self = Self(73);
    /// Pole.
    pub const POLE: Self = Self(80);
    /// Traffic sign.
    pub const TRAFFIC_SIGN: Self = Self(81);
    /// Other object.
    pub const OTHER_OBJECT: Self = Self(99);
    /// A return from fog (backscatter of the medium; ours, not a SemanticKITTI class).
    pub const FOG: Self = Self(150);
    /// A return from a raindrop in the beam (ours).
    pub const RAIN: Self = Self(151);
    /// A return from a snowflake in the beam (ours).
    pub const SNOW: Self = Self(152);

    /// The weather classes: fog, rain, snow.
    pub const WEATHER: [Self; 3] = [Self::FOG, Self::RAIN, Self::SNOW];

    /// Whether this is a return from the weather (fog, rain or snow) rather than a surface.
    pub fn is_weather(self) -> bool {
        (150..=152).contains(&self.0)
    }

    /// The ground classes: road, parking, sidewalk, other-ground, lane-marking, terrain.
    pub const GROUND: [Self; 6] =
        [Self::ROAD, Self::PARKING, Self::SIDEWALK, Self::OTHER_GROUND, Self::LANE_MARKING, Self::TERRAIN];

    /// Whether this class counts as ground truth "ground".
    pub fn is_ground(self) -> bool {
        // A bit per class id from `BASE` on (every ground id lies within 64 of it, checked at
        // compile time): one 64-bit shift, no search.
        const BASE: u16 = 40;
        const MASK: u64 = {
            let mut m = 0u64;
            let mut k = 0;
            while k < SemanticClass::GROUND.len() {
                let id = SemanticClass::GROUND[k].0;
                assert!(id >= BASE && id - BASE < 64, "a ground id outside BASE .. BASE + 64");
                m |= 1u64 << (id - BASE);
                k += 1;
            }
            m
        };
        let k = self.0.wrapping_sub(BASE);
        k < 64 && (MASK >> k) & 1 == 1
    }

    /// The id a SemanticKITTI `.label` file holds for this class: the class itself, except our
    /// [`Self::BUSH`] (73), which SemanticKITTI counts as 70 vegetation.
    pub fn semantic_kitti_id(self) -> u16 {
        match self {
            Self::BUSH => Self::VEGETATION.0,
            c => c.0,
        }
    }

    /// The nearest ASPRS (LAS 1.4) classification: ground classes 2 (ground), bushes 4 (medium
    /// vegetation), canopy and trunks 5 (high vegetation), building 6, and the user-definable
    /// classes 64.. for the rest: car 64, truck 65, other-vehicle 66, person 67, fence 68,
    /// other-structure 69, pole 70, traffic-sign 71, other-object 72; weather returns (fog, rain,
    /// snow) 18 (high noise, the class for returns from the air); anything else (unlabeled
    /// included) 1 (unclassified).
    pub fn las_class(self) -> u8 {
        if self.is_ground() {
            return 2;
        }
        match self.0 {
            150..=152 => 18,
            73 => 4,
            70 | 71 => 5,
            50 => 6,
            10 => 64,
            18 => 65,
            20 => 66,
            30 => 67,
            51 => 68,
            52 => 69,
            80 => 70,
            81 => 71,
            99 => 72,
            _ => 1,
        }
    }

    /// The SemanticKITTI name of the class (ours for [`Self::BUSH`]: `"bush"`), or `"other"`.
    pub fn name(self) -> &'static str {
        match self.0 {
            0 => "unlabeled",
            10 => "car",
            18 => "truck",
            20 => "other-vehicle",
            30 => "person",
            40 => "road",
            44 => "parking",
            48 => "sidewalk",
            49 => "other-ground",
            50 => "building",
            51 => "fence",
            52 => "other-structure",
            60 => "lane-marking",
            70 => "vegetation",
            71 => "trunk",
            72 => "terrain",
            73 => "bush",
            80 => "pole",
            81 => "traffic-sign",
            99 => "other-object",
            150 => "fog",
            151 => "rain",
            152 => "snow",
            _ => "other",
        }
    }

    /// The SemanticKITTI colour of the class (RGB), for pictures.
    pub fn color(self) -> [u8; 3] {
        match self.0 {
            10 => [100, 150, 245],
            18 => [80, 30, 180],
            20 => [0, 0, 255],
            30 => [255, 30, 30],
            40 => [255, 0, 255],
            44 => [255, 150, 255],
            48 => [75, 0, 75],
            49 => [175, 0, 75],
            50 => [255, 200, 0],
            51 => [255, 120, 50],
            52 => [255, 150, 0],
            60 => [150, 255, 170],
            70 => [0, 175, 0],
            71 => [135, 60, 0],
            72 => [150, 240, 80],
            // Bushes: a blue-green apart from canopy green and terrain (seed 002 draws them blue).
            73 => [0, 120, 160],
            80 => [255, 240, 150],
            81 => [255, 0, 0],
            150 => [200, 200, 200],
            151 => [90, 160, 255],
            152 => [240, 250, 255],
            _ => [128, 128, 128],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ground_set_is_the_six_ground_classes() {
        let ground: Vec<u16> = (0..=u16::MAX).filter(|&id| SemanticClass(id).is_ground()).collect();
        assert_eq!(ground, vec![40, 44, 48, 49, 60, 72]);
    }

    #[test]
    fn bush_is_ours_and_maps_to_vegetation_in_kitti_and_medium_vegetation_in_las() {
        assert_eq!((SemanticClass::BUSH.0, SemanticClass::BUSH.name()), (73, "bush"));
        assert_eq!(SemanticClass::BUSH.semantic_kitti_id(), 70);
        assert_eq!(SemanticClass::VEGETATION.semantic_kitti_id(), 70);
        assert_eq!(SemanticClass::TRUNK.semantic_kitti_id(), 71);
        assert_eq!(SemanticClass::CAR.semantic_kitti_id(), 10);
        assert_eq!(SemanticClass::BUSH.las_class(), 4);
        assert_eq!(SemanticClass::VEGETATION.las_class(), 5);
        assert_eq!(SemanticClass::TRUNK.las_class(), 5);
        assert_eq!(SemanticClass::TERRAIN.las_class(), 2);
        assert_eq!(SemanticClass::UNLABELED.las_class(), 1);
        let colours: std::collections::BTreeSet<[u8; 3]> =
            [70, 71, 72, 73].map(|id| SemanticClass(id).color()).into_iter().collect();
        assert_eq!(colours.len(), 4, "vegetation, trunk, terrain and bush are told apart in pictures");
    }
}
