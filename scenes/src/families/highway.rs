//! `highway`: a motorway with `lanes` lanes in the ego's direction (+x), dashed lane markings and
//! solid edge lines (exactly coplanar with the road: cut out of the road surface by grid lines), a
//! concrete median barrier, an opposite carriageway, guard rails on both outer edges, embankments
//! falling to the surrounding fields, and traffic (cars, vans, trucks) at varying gaps.

use glam::Vec3;
use rand::RngExt;
use serde::Deserialize;
use sim::{SceneMesh, SemanticClass, Surface};

use super::{Family, Generated, rng};
use crate::error::{SceneError, check, check_count};
use crate::grid::{Grid, axis};
use crate::objects::{self, Ids};

/// Dash length of the lane markings, metres (a multiple of the 2 m grid so dashes need no extra lines).
pub const DASH_M: f32 = 6.0;
/// Dash period (dash + gap), metres.
pub const DASH_PERIOD_M: f32 = 18.0;
/// Width of dashed lane markings, metres.
pub const DASH_WIDTH_M: f32 = 0.15;
/// Width of solid edge lines, metres.
pub const EDGE_LINE_WIDTH_M: f32 = 0.3;

/// Parameters of `highway`.
#[derive(Deserialize, Debug, Clone)]
#[serde(default, deny_unknown_fields)]
pub struct Params {
    /// Lanes per direction (2 ..= 5, default 3); the ego vehicle drives in the second lane from the right.
    pub lanes: u32,
    /// Lane width, metres (2.5 ..= 5, default 3.75).
    pub lane_width_m: f32,
    /// Vehicles per lane per kilometre in the ego's direction (0 ..= 100, default 25).
    pub vehicles_per_km: f32,
    /// Smallest gap between vehicles, metres (4 ..= 100, default 10).
    pub min_gap_m: f32,
    /// Height of the road above the surrounding fields, metres (0 ..= 8, default 2).
    pub embankment_height_m: f32,
    /// Slope of the embankments, degrees (10 ..= 45, default 25).
    pub embankment_slope_deg: f32,
    /// Side of the square terrain, metres (200 ..= 1000, default 400).
    pub size_m: f32,
}

impl Default for Params {
    fn default() -> Self {
        Self {
            lanes: 3,
            lane_width_m: 3.75,
            vehicles_per_km: 25.0,
            min_gap_m: 10.0,
            embankment_height_m: 2.0,
            embankment_slope_deg: 25.0,
            size_m: 400.0,
        }
    }
}

/// Cross-section of the highway (y coordinates, metres).
struct Section {
    right_edge: f32,
    left_edge: f32,
    median_y: f32,
    opp_right: f32,
    opp_left: f32,
    rail_right: f32,
    rail_left: f32,
    bank_right: f32,
    bank_left: f32,
    run: f32,
}

impl Params {
    fn section(&self) -> Section {
        let lw = self.lane_width_m;
        let right_edge = -1.5 * lw;
        let left_edge = right_edge + self.lanes as f32 * lw;
        let median_y = left_edge + 2.0;
        let opp_right = median_y + 2.0;
        let opp_left = opp_right + self.lanes as f32 * lw;
        let run = self.embankment_height_m / self.embankment_slope_deg.to_radians().tan();
        Section {
            right_edge,
            left_edge,
            median_y,
            opp_right,
            opp_left,
            rail_right: right_edge - 3.0,
            rail_left: opp_left + 3.0,
            bank_right: right_edge - 3.5,
            bank_left: opp_left + 3.5,
            run,
        }
    }
}

impl Family for Params {
    fn validate(&self) -> Result<(), SceneError> {
        check_count("lanes", self.lanes, 2, 5)?;
        check("lane_width_m", self.lane_width_m, 2.5, 5.0)?;
        check("vehicles_per_km", self.vehicles_per_km, 0.0, 100.0)?;
        check("min_gap_m", self.min_gap_m, 4.0, 100.0)?;
        check("embankment_height_m", self.embankment_height_m, 0.0, 8.0)?;
        check("embankment_slope_deg", self.embankment_slope_deg, 10.0, 45.0)?;
        check("size_m", self.size_m, 200.0, 1000.0)
    }

    fn build(&self, seed: u64) -> Generated {
        let half = 0.5 * self.size_m;
        let lw = self.lane_width_m;
        let sec = self.section();
        // Marking bands (y ranges) and whether they are dashed.
        let mut bands: Vec<(f32, f32, bool)> = Vec::new();
        for (lo, hi) in [(sec.right_edge, sec.left_edge), (sec.opp_right, sec.opp_left)] {
            bands.push((lo + 0.2, lo + 0.2 + EDGE_LINE_WIDTH_M, false));
            bands.push((hi - 0.2 - EDGE_LINE_WIDTH_M, hi - 0.2, false));
            for k in 1..self.lanes {
                let y = lo + k as f32 * lw;
                bands.push((y - 0.5 * DASH_WIDTH_M, y + 0.5 * DASH_WIDTH_M, true));
            }
        }
        let mut ybreaks: Vec<f32> = bands.iter().flat_map(|b| [b.0, b.1]).collect();
        let (bl, bh) = (sec.bank_right, sec.bank_left);
        ybreaks.extend([
            sec.right_edge,
            sec.left_edge,
            sec.opp_right,
            sec.opp_left,
            bl,
            bl - sec.run,
            bh,
            bh + sec.run,
        ]);
        let xs = axis(half, 80.0, 1.0, 2.0, &[], &[]);
        let ys = axis(half, 40.0, 1.0, 2.0, &ybreaks, &[]);
        let h = self.embankment_height_m;
        let run = sec.run.max(1e-6);
        let height = move |_: f32, y: f32| {
            let out = if y < bl {
                (bl - y) / run
            } else if y > bh {
                (y - bh) / run
            } else {
                0.0
            };
            -h * out.min(1.0)
        };
        let on_road = |y: f32| {
            (sec.right_edge - 2.5..sec.left_edge + 1.0).contains(&y)
                || (sec.opp_right - 1.0..sec.opp_left + 2.5).contains(&y)
        };
        let mut mesh = SceneMesh::new();
        Grid::new(xs, ys).push(&mut mesh, height, |c| {
            let marked = bands.iter().any(|&(lo, hi, dashed)| {
                c.y > lo && c.y < hi && (!dashed || (c.x + 1000.0 * DASH_PERIOD_M).rem_euclid(DASH_PERIOD_M) < DASH_M)
            });
            let class = if marked {
                SemanticClass::LANE_MARKING
            } else if on_road(c.y) {
                SemanticClass::ROAD
            } else {
                SemanticClass::TERRAIN
            };
            Some(Surface::stuff(class))
        });
        let mut ids = Ids::default();
        let ext = half - 2.0;
        objects::wall(&mut mesh, &mut ids, Vec3::new(0.0, sec.median_y, 0.0), 0.0, Vec3::new(2.0 * ext, 0.5, 0.9));
        objects::guard_rail(
            &mut mesh,
            &mut ids,
            Vec3::new(-ext, sec.rail_right, 0.0),
            Vec3::new(ext, sec.rail_right, 0.0),
        );
        objects::guard_rail(
            &mut mesh,
            &mut ids,
            Vec3::new(ext, sec.rail_left, 0.0),
            Vec3::new(-ext, sec.rail_left, 0.0),
        );
        let mut r = rng(seed, 5);
        let mean_gap = (1000.0 / self.vehicles_per_km.max(1e-3)).max(self.min_gap_m);
        let mut lane_traffic =
            |mesh: &mut SceneMesh, ids: &mut Ids, y: f32, yaw: f32, per_km_scale: f32, ego_lane: bool| {
                if self.vehicles_per_km == 0.0 {
                    return;
                }
                let mut x = -ext + r.random_range(0.0..mean_gap);
                while x < ext - 8.0 {
                    let kind = r.random_range(0..20u32);
                    let len = match kind {
                        0..=13 => 4.5,
                        14..=16 => 5.2,
                        _ => 12.0,
                    };
                    let c = x + 0.5 * len;
                    if !(ego_lane && c.abs() < 0.5 * len + 6.0) {
                        let p = Vec3::new(c, y, 0.0);
                        match kind {
                            0..=13 => objects::car(mesh, ids, p, yaw),
                            14..=16 => objects::van(mesh, ids, p, yaw),
                            _ => objects::truck(mesh, ids, p, yaw),
                        };
                    }
                    let gap = self.min_gap_m + r.random_range(0.0..2.0f32) * (mean_gap - self.min_gap_m) / per_km_scale;
                    x += len + gap;
                }
            };
        for k in 0..self.lanes {
            let y = sec.right_edge + (k as f32 + 0.5) * lw;
            lane_traffic(&mut mesh, &mut ids, y, 0.0, 1.0, k == 1);
        }
        for k in 0..self.lanes {
            let y = sec.opp_left - (k as f32 + 0.5) * lw;
            lane_traffic(&mut mesh, &mut ids, y, std::f32::consts::PI, 0.6, false);
        }
        // Signs on the right shoulder and lighting poles in the median.
        let mut x = -ext + 30.0;
        while x < ext {
            objects::sign(&mut mesh, &mut ids, Vec3::new(x, sec.rail_right + 0.8, 0.0), std::f32::consts::PI);
            objects::pole(&mut mesh, &mut ids, Vec3::new(x + 25.0, sec.median_y, 0.9), 9.0);
            x += 100.0;
        }
        Generated { mesh, ego_ground_z_m: 0.0, ids }
    }
}
