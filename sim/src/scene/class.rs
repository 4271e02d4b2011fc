//! Semantic classes, using the SemanticKITTI label ids.

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
    /// Vegetation (canopy, bushes).
    pub const VEGETATION: Self = Self(70);
    /// Trunk.
    pub const TRUNK: Self = Self(71);
    /// Terrain.
    pub const TERRAIN: Self = Self(72);
    /// Pole.
    pub const POLE: Self = Self(80);
    /// Traffic sign.
    pub const TRAFFIC_SIGN: Self = Self(81);
    /// Other object.
    pub const OTHER_OBJECT: Self = Self(99);

    /// The ground classes: road, parking, sidewalk, other-ground, lane-marking, terrain.
    pub const GROUND: [Self; 6] =
        [Self::ROAD, Self::PARKING, Self::SIDEWALK, Self::OTHER_GROUND, Self::LANE_MARKING, Self::TERRAIN];

    /// Whether this class counts as ground truth "ground".
    pub fn is_ground(self) -> bool {
        Self::GROUND.contains(&self)
    }

    /// The SemanticKITTI name of the class, or `"other"`.
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
            80 => "pole",
            81 => "traffic-sign",
            99 => "other-object",
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
            80 => [255, 240, 150],
            81 => [255, 0, 0],
            _ => [128, 128, 128],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ground_set_is_the_six_ground_classes() {
        let ground: Vec<u16> = (0..=u16::from(u8::MAX)).filter(|&id| SemanticClass(id).is_ground()).collect();
        assert_eq!(ground, vec![40, 44, 48, 49, 60, 72]);
    }
}
