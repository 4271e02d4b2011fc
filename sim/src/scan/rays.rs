//! A merged row's rays: the sensor pose at each distinct shot time and the world rays of the row's
//! fired beams (kept for a standing vehicle, rebuilt per frame for a moving one).

use glam::{Affine3A, Vec3};

use super::Scanner;
use crate::cast::{Beam, BeamSet, Ray};
use crate::effects::cast_limit_m;
use crate::sensor::{Firing, ScanPattern};

impl Scanner<'_> {
    /// The world rays of merged row `row` in frame `frame`, each from the vehicle pose at its shot's
    /// own time, in column order (coherent for the caster). With multi-echo sensors each beam is
    /// followed by two sub-beams at the horizontal edges of its divergence cone.
    pub fn row_rays(&self, frame: usize, row: usize) -> RowRays {
        let mut row_beams = RowBeams::default();
        let shot_poses = self.shot_poses(frame);
        self.fill_row_beams(frame, row, &mut row_beams, &shot_poses);
        let (s, ring) = self.row_source[row];
        let beams = row_beams
            .beam_col
            .iter()
            .enumerate()
            .map(|(b, &c)| {
                let f = self.patterns[s].at(ring, c as usize).copied().unwrap_or(Firing {
                    origin_in_sensor: Vec3::ZERO,
                    dir_in_sensor: Vec3::ZERO,
                    time_s: 0.0,
                });
                let pose = row_beams
                    .beam_shot
                    .get(b)
                    .map_or(row_beams.static_pose, |&k| shot_poses[s][k as usize].world_from_sensor);
                (c as usize, f, pose)
            })
            .collect();
        RowRays { beams, rays: row_beams.rays, sub_rays: row_beams.sub_rays }
    }

    /// Every merged row's beams in the sensor frame, in the order [`Scanner::fill_row_beams`] makes
    /// their rays (rows, fired columns, sub-rays), for a caster that makes rays on a device
    /// ([`Caster::cast_beams`]). Each beam is placed by its sensor's pose at its shot time: a
    /// sensor with at most [`MAX_KEY_POSES`] distinct shot times has a pose per shot time (the
    /// host's poses exactly); one with more (a VLP-16 fires every laser at its own time) has
    /// [`MAX_KEY_POSES`] key poses spread evenly over its shots, each beam blended between the two
    /// around its time.
    ///
    /// [`Caster::cast_beams`]: crate::cast::Caster::cast_beams
    pub(super) fn device_beams(&self) -> Option<DeviceBeams> {
        let mut first_key = Vec::with_capacity(self.shot_times.len());
        let mut key_times_s = Vec::with_capacity(self.shot_times.len());
        for shots in &self.shot_times {
            first_key.push(key_times_s.iter().map(Vec::len).sum::<usize>());
            key_times_s.push(match shots.times.as_slice() {
                t if t.len() <= MAX_KEY_POSES => t.to_vec(),
                t => {
                    let (t0, t1) = (t[0], t[t.len() - 1]);
                    (0..MAX_KEY_POSES).map(|j| t0 + (t1 - t0) * j as f64 / (MAX_KEY_POSES - 1) as f64).collect()
                }
            });
        }
        // The key pose and blend of each shot time of each sensor.
        let placed: Vec<Vec<(u32, f32)>> = self
            .shot_times
            .iter()
            .zip(&key_times_s)
            .zip(&first_key)
            .map(|((shots, keys), &first)| {
                let exact = shots.times.len() <= MAX_KEY_POSES;
                shots
                    .times
                    .iter()
                    .enumerate()
                    .map(|(k, &t)| {
                        if exact {
                            return ((first + k) as u32, 0.0);
                        }
                        let (t0, t1) = (keys[0], keys[keys.len() - 1]);
                        let u = (t - t0) / (t1 - t0) * (keys.len() - 1) as f64;
                        let j = (u.floor() as usize).min(keys.len() - 1);
                        let blend = ((u - j as f64) as f32).clamp(0.0, 1.0 - f32::EPSILON);
                        ((first + j) as u32, if j + 1 < keys.len() { blend } else { 0.0 })
                    })
                    .collect()
            })
            .collect();
        let mut beams = Vec::new();
        for &(s, ring) in &self.row_source {
            let pattern = &self.patterns[s];
            let m = &self.measurements[s];
            let t_max_m = cast_limit_m(m);
            let sub_rays = m.max_echoes > 1 && m.beam_divergence_rad > 0.0;
            let off = (0.5 * m.beam_divergence_rad).tan();
            let firings = &pattern.firings[ring * pattern.cols..(ring + 1) * pattern.cols];
            let shot_of = &self.shot_times[s].index[ring * pattern.cols..(ring + 1) * pattern.cols];
            for (f, &shot) in firings.iter().zip(shot_of) {
                let Some(f) = f else { continue };
                let (pose, pose_blend) = placed[s][shot as usize];
                // The firing's own direction, which the host's rays normalise after turning it, and
                // the divergence sub-rays turned sideways as `fill_row_beams` turns them.
                let beam = Beam {
                    origin_in_sensor: f.origin_in_sensor,
                    dir_in_sensor: f.dir_in_sensor,
                    t_max_m,
                    pose,
                    pose_blend,
                    side_offset: 0.0,
                };
                beams.push(beam);
                if sub_rays {
                    for sign in [-1.0f32, 1.0] {
                        beams.push(Beam { side_offset: sign * off, ..beam });
                    }
                }
            }
        }
        let poses = first_key.last().copied().unwrap_or(0) + key_times_s.last().map_or(0, Vec::len);
        Some(DeviceBeams { set: BeamSet::new(beams, poses).ok()?, key_times_s })
    }

    /// The poses of frame `frame` for [`Scanner::device_beams`]: each sensor's pose at each of its
    /// key times.
    pub(super) fn device_poses(&self, beams: &DeviceBeams, frame: usize) -> Vec<Affine3A> {
        let start_time_s = frame as f64 * self.frame_period_s;
        beams
            .key_times_s
            .iter()
            .zip(&self.vehicle_from_sensor)
            .flat_map(|(keys, &vehicle_from_sensor)| {
                keys.iter().map(move |&t| self.track.at(start_time_s + t).world_from_vehicle() * vehicle_from_sensor)
            })
            .collect()
    }

    /// A moving vehicle's pose in frame `frame` at each distinct shot time of each sensor (indexed
    /// like [`ShotTimes::times`]), computed once per frame: many beams share a shot time (all
    /// lasers of an OS1 column fire together). Empty for a standing vehicle.
    pub(super) fn shot_poses(&self, frame: usize) -> Vec<Vec<ShotPose>> {
        use rayon::prelude::*;
        if self.track.is_static() {
            return Vec::new();
        }
        let start_time_s = frame as f64 * self.frame_period_s;
        self.shot_times
            .iter()
            .zip(&self.vehicle_from_sensor)
            .map(|(shots, &vehicle_from_sensor)| {
                shots
                    .times
                    .par_iter()
                    .map(|&t| {
                        ShotPose::new(
                            self.track.at(start_time_s + t).world_from_vehicle() * vehicle_from_sensor,
                            vehicle_from_sensor,
                        )
                    })
                    .collect()
            })
            .collect()
    }

    /// Fills `out` with the beams and rays of merged row `row` in frame `frame` (see
    /// [`Scanner::row_rays`]); `shot_poses` is [`Scanner::shot_poses`] of the frame.
    pub(super) fn fill_row_beams(&self, frame: usize, row: usize, out: &mut RowBeams, shot_poses: &[Vec<ShotPose>]) {
        let (s, ring) = self.row_source[row];
        let pattern = &self.patterns[s];
        let m = &self.measurements[s];
        let vehicle_from_sensor = self.vehicle_from_sensor[s];
        let static_world_from_sensor = self.track.frame_start(frame).world_from_vehicle() * vehicle_from_sensor;
        let moving = !self.track.is_static();
        let t_max = cast_limit_m(m);
        let sub_rays = if m.max_echoes > 1 && m.beam_divergence_rad > 0.0 { 3 } else { 1 };
        let off = (0.5 * m.beam_divergence_rad).tan();
        let RowBeams { rays, beam_col, beam_shot, beam_of_col, sub_rays: out_sub_rays, static_pose } = out;
        *out_sub_rays = sub_rays;
        *static_pose = static_world_from_sensor;
        rays.clear();
        beam_col.clear();
        beam_shot.clear();
        beam_of_col.clear();
        beam_of_col.resize(pattern.cols, NO_BEAM);
        let firings = &pattern.firings[ring * pattern.cols..(ring + 1) * pattern.cols];
        let shot_of = &self.shot_times[s].index[ring * pattern.cols..(ring + 1) * pattern.cols];
        for (c, f) in firings.iter().enumerate() {
            let Some(f) = f else { continue };
            let world_from_sensor =
                if moving { shot_poses[s][shot_of[c] as usize].world_from_sensor } else { static_world_from_sensor };
            let origin = world_from_sensor.transform_point3(f.origin_in_sensor);
            let dir = world_from_sensor.transform_vector3(f.dir_in_sensor).normalize();
            rays.push(Ray { origin, dir, t_max });
            if sub_rays > 1 {
                let side = world_from_sensor.transform_vector3(f.dir_in_sensor.cross(Vec3::Z)).normalize_or_zero();
                for sign in [-1.0f32, 1.0] {
                    rays.push(Ray { origin, dir: (dir + side * (sign * off)).normalize(), t_max });
                }
            }
            beam_of_col[c] = beam_col.len() as u32;
            beam_col.push(c as u32);
            if moving {
                beam_shot.push(shot_of[c]);
            }
        }
    }
}

/// Key poses per sensor and frame at most for [`Scanner::device_beams`]: a 0.1 s frame of a
/// vehicle turning at 2 rad/s then turns 0.8 mrad between keys, and a direction blended linearly
/// between two keys is off by about (0.8 mrad)^2 / 8 = 0.08 urad, 0.01 mm at 120 m.
pub(super) const MAX_KEY_POSES: usize = 257;

/// A rig's beams kept on a device and the key times (seconds after the frame start) of each
/// sensor's poses.
pub(super) struct DeviceBeams {
    pub(super) set: BeamSet,
    key_times_s: Vec<Vec<f64>>,
}

/// The sensor pose at one shot.
#[derive(Clone, Copy, Debug)]
pub(super) struct ShotPose {
    /// Sensor pose in the world at the shot.
    pub(super) world_from_sensor: Affine3A,
    /// Rotation taking world vectors to the vehicle frame at the shot:
    /// `vehicle_from_sensor * transpose(world_from_sensor)`.
    pub(super) vehicle_from_world: glam::Mat3A,
}

impl ShotPose {
    pub(super) fn new(world_from_sensor: Affine3A, vehicle_from_sensor: Affine3A) -> Self {
        Self {
            world_from_sensor,
            vehicle_from_world: vehicle_from_sensor.matrix3 * world_from_sensor.matrix3.transpose(),
        }
    }
}

/// A sensor's distinct shot times (seconds after the frame start) and which one each firing uses.
pub(super) struct ShotTimes {
    /// Distinct shot times, increasing.
    pub(super) times: Vec<f64>,
    /// Per pattern cell (row-major), the index of its shot time in `times` (0 where it does not fire).
    pub(super) index: Vec<u32>,
}

impl ShotTimes {
    pub(super) fn new(pattern: &ScanPattern) -> Self {
        let mut times: Vec<f64> = pattern.firings.iter().flatten().map(|f| f.time_s).collect();
        times.sort_by(f64::total_cmp);
        times.dedup_by(|a, b| a.to_bits() == b.to_bits());
        let index = pattern
            .firings
            .iter()
            .map(|f| f.map_or(0, |f| times.binary_search_by(|t| t.total_cmp(&f.time_s)).unwrap_or_default() as u32))
            .collect();
        Self { times, index }
    }
}

/// Marks an unfired sensor column in [`RowBeams::beam_of_col`].
pub(super) const NO_BEAM: u32 = u32::MAX;

/// The beams of one merged row and their rays (see [`Scanner::row_rays`]).
#[derive(Clone, Debug, Default)]
pub(super) struct RowBeams {
    /// The row's rays, `sub_rays` per fired beam.
    pub(super) rays: Vec<Ray>,
    /// Rays per beam.
    pub(super) sub_rays: usize,
    /// Sensor column of each fired beam.
    pub(super) beam_col: Vec<u32>,
    /// Shot-time index ([`ShotTimes::times`]) of each fired beam (moving vehicle only, else empty).
    pub(super) beam_shot: Vec<u32>,
    /// `world_from_sensor` at the start of the frame: the pose of every beam of a standing vehicle.
    pub(super) static_pose: Affine3A,
    /// Beam index of each sensor column, [`NO_BEAM`] where the sensor does not fire.
    pub(super) beam_of_col: Vec<u32>,
}

/// The rays of one merged row (see [`Scanner::row_rays`]).
pub struct RowRays {
    /// `(sensor column, firing, world_from_sensor at the shot time)` per fired beam.
    pub beams: Vec<(usize, Firing, Affine3A)>,
    /// `sub_rays` rays per beam, the beam's own ray first.
    pub rays: Vec<Ray>,
    /// Rays per beam (3 with multi-echo divergence sampling, else 1).
    pub sub_rays: usize,
}
