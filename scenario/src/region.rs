//! Regions: the parts of a scanned cloud to assert on, as masks over its cells (one `bool` per
//! cell, all echo planes, grid order; cells without a return are never in a region).
//!
//! Every region is derived from the cloud's labels, instances and true surface normals and from the
//! scene's own geometry parameters (`ramp`'s `distance_m`, `basin`'s edges, ...). Points and normals
//! are taken to the world frame with the frame's `world_from_vehicle` (exact for a standing
//! vehicle; for a moving one, to within the motion during the sweep).

use std::fmt;

use glam::Vec3;
use sim::SemanticClass;
use sim::scan::Frame;

use crate::error::{Result, ScenarioError};
use crate::geometry::Geometry;

/// Tolerance of "on the surface", metres: a return within this height of the analytic surface.
pub const ON_SURFACE_M: f32 = 0.05;
/// Largest angle between a flat top's normal and the ground's up-normal, degrees.
pub const FLAT_TOP_MAX_TILT_DEG: f32 = 10.0;
/// Smallest height of a flat top above the bare ground under it, metres.
pub const FLAT_TOP_MIN_HEIGHT_M: f32 = 0.25;

/// A part of the cloud to score decisions on.
///
/// ```
/// use groundtruth_scenario::{Region, Scenario};
/// let scan = Scenario::family("ramp").param("slope_deg", 10.0).ideal(true).scan()?;
/// let mask = scan.region_mask(0, &Region::RampSurface)?;
/// let c = &scan.frames()[0].cloud;
/// // Every ramp-surface return is ground and lies on the 10 deg plane.
/// for i in (0..c.len()).filter(|&i| mask[i]) {
///     assert!(c.ground[i]);
///     let p = c.point_in_vehicle[i];
///     assert!((p.z - (p.x - 15.0) * 10f32.to_radians().tan()).abs() < 0.05);
/// }
/// # Ok::<(), groundtruth_scenario::ScenarioError>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub enum Region {
    /// Every return.
    All,
    /// Every return labelled ground (road, parking, sidewalk, other-ground, terrain, lane marking).
    Ground,
    /// Every return not labelled ground.
    NonGround,
    /// `ramp` only: ground returns on the sloped part of the corridor: `distance_m <= x <=
    /// distance_m + length_m`, `|y| < width_m / 2`, within [`ON_SURFACE_M`] of the ramp plane.
    RampSurface,
    /// `basin` only: ground returns on the flat bottom: inside the bottom's edges along and across
    /// the road (`along_edges()[1..=2]`, `cross_edges()[1..=2]`) and within [`ON_SURFACE_M`] of
    /// `-depth_m`.
    BasinFloor,
    /// `basin` only: the level ground beyond the basin (the "elevated target" after a lowered
    /// surface): ground returns farther from the road than the basin's far top edge
    /// (`cross_edges()[3]`, on the basin's side) and along the basin's length
    /// (`along_edges()[0] ..= along_edges()[3]`).
    BeyondBasin,
    /// `elevated` only: ground returns on the plateau tops (inside `elevated::PLATEAUS`, within
    /// [`ON_SURFACE_M`] of `plateau_height_m`): raised, but ground.
    Plateau,
    /// Flat raised tops that are not ground: non-ground returns whose true normal is within
    /// [`FLAT_TOP_MAX_TILT_DEG`] of the bare ground's up-normal and which lie at least
    /// [`FLAT_TOP_MIN_HEIGHT_M`] above the bare ground under them (car, van and truck roofs and
    /// bonnets, loading docks, platforms, table tops). Any family.
    FlatRaisedTops,
    /// The [`Region::FlatRaisedTops`] of vehicles only (classes car, truck, other-vehicle).
    VehicleRoofs,
    /// `hill` only: ground returns on the constant slope the ego vehicle stands on, from behind it
    /// up to the start of the crest (`x <= crest_x_m - crest_length_m / 2`).
    HillSlope,
    /// Vegetation: canopy (70), trunks (71) and bushes (73).
    Vegetation,
    /// Returns from the weather: fog (150), rain (151) and snow (152) (never ground; a method that
    /// calls them ground reports false ground).
    Weather,
    /// Returns whose range is in `min_m ..max_m` (metres from the beam origin).
    RangeBand {
        /// Inclusive lower bound, metres.
        min_m: f32,
        /// Exclusive upper bound, metres.
        max_m: f32,
    },
    /// Returns of one semantic class.
    Class(SemanticClass),
    /// Returns of one object instance (0 is "stuff": ground, walls).
    Instance(u32),
}

impl fmt::Display for Region {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::All => write!(f, "all"),
            Self::Ground => write!(f, "ground"),
            Self::NonGround => write!(f, "non-ground"),
            Self::RampSurface => write!(f, "ramp-surface"),
            Self::BasinFloor => write!(f, "basin-floor"),
            Self::BeyondBasin => write!(f, "beyond-basin"),
            Self::Plateau => write!(f, "plateau"),
            Self::FlatRaisedTops => write!(f, "flat-raised-tops"),
            Self::VehicleRoofs => write!(f, "vehicle-roofs"),
            Self::HillSlope => write!(f, "hill-slope"),
            Self::Vegetation => write!(f, "vegetation"),
            Self::Weather => write!(f, "weather"),
            Self::RangeBand { min_m, max_m } => write!(f, "range {min_m}-{max_m} m"),
            Self::Class(c) => write!(f, "class {}", c.name()),
            Self::Instance(i) => write!(f, "instance {i}"),
        }
    }
}

impl Region {
    fn needs(&self, geometry: &Geometry, family: &str) -> Result<()> {
        let needs = match (self, geometry) {
            (Self::RampSurface, Geometry::Ramp(_))
            | (Self::BasinFloor | Self::BeyondBasin, Geometry::Basin(_))
            | (Self::Plateau, Geometry::Elevated(_))
            | (Self::HillSlope, Geometry::Hill(_)) => return Ok(()),
            (Self::RampSurface, _) => "ramp",
            (Self::BasinFloor | Self::BeyondBasin, _) => "basin",
            (Self::Plateau, _) => "elevated",
            (Self::HillSlope, _) => "hill",
            (Self::RangeBand { min_m, max_m }, _) => {
                if !(min_m.is_finite() && max_m.is_finite() && *min_m >= 0.0 && min_m < max_m) {
                    return Err(ScenarioError::invalid(
                        "RangeBand",
                        format!("{min_m} .. {max_m}"),
                        "finite, 0 <= min_m < max_m",
                    ));
                }
                return Ok(());
            }
            _ => return Ok(()),
        };
        Err(ScenarioError::RegionFamily { region: self.to_string(), needs, family: family.to_string() })
    }

    /// The mask of this region over `frame`'s cloud (checked against the scene's family).
    pub(crate) fn mask(&self, frame: &Frame, geometry: &Geometry, family: &str) -> Result<Vec<bool>> {
        self.needs(geometry, family)?;
        let c = &frame.cloud;
        let wfv = frame.world_from_vehicle;
        let flat_cos = FLAT_TOP_MAX_TILT_DEG.to_radians().cos();
        let inside = |i: usize| -> bool {
            let label = c.label[i];
            let ground = c.ground[i];
            let world = || wfv.transform_point3(c.point_in_vehicle[i]);
            let flat_top = || {
                let p: Vec3 = world();
                let n = wfv.transform_vector3(c.normal[i]);
                !ground
                    && n.dot(geometry.ground_up(p.x, p.y)) >= flat_cos
                    && p.z - geometry.ground_z_m(p.x, p.y) >= FLAT_TOP_MIN_HEIGHT_M
            };
            match self {
                Self::All => true,
                Self::Ground => ground,
                Self::NonGround => !ground,
                Self::RampSurface => {
                    let Geometry::Ramp(r) = geometry else { return false };
                    let p = world();
                    ground
                        && (r.distance_m..=r.distance_m + r.length_m).contains(&p.x)
                        && p.y.abs() < 0.5 * r.width_m
                        && (p.z - r.profile_z(p.x)).abs() <= ON_SURFACE_M
                }
                Self::BasinFloor => {
                    let Geometry::Basin(b) = geometry else { return false };
                    let p = world();
                    let s = if b.side == scenes::families::basin::Side::Right { -1.0 } else { 1.0 };
                    let (a, x) = (b.along_edges(), b.cross_edges());
                    ground
                        && (a[1]..=a[2]).contains(&p.x)
                        && (x[1]..=x[2]).contains(&(s * p.y))
                        && (p.z + b.depth_m).abs() <= ON_SURFACE_M
                }
                Self::BeyondBasin => {
                    let Geometry::Basin(b) = geometry else { return false };
                    let p = world();
                    let s = if b.side == scenes::families::basin::Side::Right { -1.0 } else { 1.0 };
                    let a = b.along_edges();
                    ground && (a[0]..=a[3]).contains(&p.x) && s * p.y >= b.cross_edges()[3]
                }
                Self::Plateau => {
                    let Geometry::Elevated(e) = geometry else { return false };
                    let p = world();
                    ground
                        && (p.z - e.plateau_height_m).abs() <= ON_SURFACE_M
                        && scenes::families::elevated::PLATEAUS
                            .iter()
                            .any(|&(x0, x1, y0, y1)| (x0..=x1).contains(&p.x) && (y0..=y1).contains(&p.y))
                }
                Self::FlatRaisedTops => flat_top(),
                Self::VehicleRoofs => {
                    matches!(label, SemanticClass::CAR | SemanticClass::TRUCK | SemanticClass::OTHER_VEHICLE)
                        && flat_top()
                }
                Self::HillSlope => {
                    let Geometry::Hill(h) = geometry else { return false };
                    ground && world().x <= h.crest_x_m - 0.5 * h.crest_length_m
                }
                Self::Vegetation => matches!(label.0, 70 | 71 | 73),
                Self::Weather => label.is_weather(),
                Self::RangeBand { min_m, max_m } => (*min_m..*max_m).contains(&c.range_m[i]),
                Self::Class(k) => label == *k,
                Self::Instance(k) => c.instance[i] == *k,
            }
        };
        Ok((0..c.len()).map(|i| c.has_return(i) && inside(i)).collect())
    }
}
