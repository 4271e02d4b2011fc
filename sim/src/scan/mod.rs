//! The scan pipeline: for each frame and each sensor row, build the world rays of the row's beams
//! at each shot's own vehicle pose, cast them, apply the measurement effects and write the cells of
//! the rig's merged ordered grid ([`crate::layout`]).
//!
//! Points are reported in the vehicle frame **at each shot's own time** (like a real sensor whose
//! driver does not compensate ego motion), so a moving vehicle's clouds show motion distortion; the
//! per-frame poses are returned with each frame so users can compensate.
//!
//! Work is split by rows of the merged grid (one rayon task per row); every random draw is keyed by
//! (seed, frame, sensor, ring, column), so output is identical at any thread count.
//!
//! Cost (the frame should cost little more than casting its rays):
//! - every plane-0 cell is written exactly once per frame (walking the merged columns with the
//!   merged -> sensor column table of [`RigLayout::sensor_col_of`]), so reused clouds need no reset;
//! - a standing vehicle's rays are the same in every frame and are built once, in [`Scanner::new`];
//!   a moving vehicle's pose is computed once per distinct shot time per frame, not per beam;
//! - rays and hits live in per-worker scratch buffers reused from row to row (they carry nothing
//!   from one row to the next, so results do not depend on the split);
//! - a row draws its noise stream only up to its last column with a hit (a prefix: same numbers);
//! - each triangle's normal and surface index sit in one 16-byte record (one cache miss per hit).

use std::sync::Arc;

use glam::Affine3A;

use crate::cast::{Backend, Caster, Ray};
use crate::cloud::OrderedCloud;
use crate::error::{Result, SimError, check_range};
use crate::layout::RigLayout;
use crate::motion::{PoseTrack, Trajectory, VehiclePose};
use crate::rig::Rig;
use crate::scene::{SceneMesh, Surface};
use crate::sensor::{Measurement, ScanPattern};

mod agreement;
mod cells;
mod pipeline;
mod rays;
mod row;

pub use agreement::{Agreement, AgreementContract};
use cells::{ExtraEcho, row_views};
use pipeline::CastAhead;
pub use rays::RowRays;
use rays::{RowBeams, ShotTimes};
use row::{RowScratch, TriangleRecord, triangle_records};

/// Largest number of frames one scan may produce.
pub const MAX_FRAMES: usize = 100_000;

/// How to scan.
#[derive(Clone, Debug, PartialEq)]
pub struct ScanConfig {
    /// Seed of every random draw (range noise).
    pub seed: u64,
    /// Number of frames (1 ..= [`MAX_FRAMES`]).
    pub frames: usize,
    /// Ego speed, metres per second (|v| <= 100).
    pub speed_m_per_s: f32,
    /// Ego yaw rate, radians per second (|w| <= 2).
    pub yaw_rate_rad_per_s: f32,
    /// Turn every measurement effect off (exact distances).
    pub ideal: bool,
    /// Ray casting backend.
    pub backend: Backend,
    /// Height of the ground under the ego vehicle at the start, metres (a hint for terrain following).
    pub ego_z_m: f32,
    /// Waypoints `[x, y]` the ego follows at `speed_m_per_s` (world frame, metres; none, or 2 or
    /// more): see [`crate::motion::Trajectory::waypoints_m`]. The yaw rate is then unused.
    pub waypoints_m: Vec<[f64; 2]>,
    /// Weather decided per beam ([`crate::effects::weather`]); `None`: the sensors as they always
    /// were (no detection threshold, no medium). Not applied with `ideal`.
    pub weather: Option<crate::effects::weather::Weather>,
}

impl Default for ScanConfig {
    fn default() -> Self {
        Self {
            seed: 0,
            frames: 1,
            speed_m_per_s: 0.0,
            yaw_rate_rad_per_s: 0.0,
            ideal: false,
            backend: Backend::Bvh,
            ego_z_m: 0.0,
            waypoints_m: Vec::new(),
            weather: None,
        }
    }
}

impl ScanConfig {
    /// Checks every field, naming the field and its allowed range.
    pub fn validate(&self) -> Result<()> {
        if self.frames == 0 || self.frames > MAX_FRAMES {
            return Err(SimError::invalid("frames", self.frames, format!("1 ..= {MAX_FRAMES}")));
        }
        check_range("speed_m_per_s", f64::from(self.speed_m_per_s), -100.0, 100.0)?;
        check_range("yaw_rate_rad_per_s", f64::from(self.yaw_rate_rad_per_s), -2.0, 2.0)?;
        check_range("ego_z_m", f64::from(self.ego_z_m), -10_000.0, 10_000.0)?;
        if let Some(w) = &self.weather {
            w.validate()?;
        }
        match self.waypoints_m.len() {
            0 => Ok(()),
            1 => Err(SimError::invalid("waypoints_m", 1, "none, or 2 or more points")),
            _ if self.speed_m_per_s <= 0.0 => {
                Err(SimError::invalid("speed_m_per_s", self.speed_m_per_s, "> 0 with waypoints"))
            }
            _ => {
                for (k, w) in self.waypoints_m.iter().enumerate() {
                    for v in w {
                        check_range(&format!("waypoints_m[{k}]"), *v, -1e6, 1e6)?;
                    }
                }
                Ok(())
            }
        }
    }
}

/// One scanned frame.
#[derive(Clone, Debug)]
pub struct Frame {
    /// Frame index.
    pub index: usize,
    /// Start of the frame, seconds since the start of the scan.
    pub start_time_s: f64,
    /// Vehicle pose at the start of the frame.
    pub vehicle_pose: VehiclePose,
    /// `vehicle_pose` as a transform.
    pub world_from_vehicle: Affine3A,
    /// The ordered labelled cloud.
    pub cloud: OrderedCloud,
}

/// A rig placed in a scene, ready to scan frames.
pub struct Scanner<'a> {
    mesh: &'a SceneMesh,
    caster: Arc<dyn Caster>,
    /// Per triangle, its world normal and surface record side by side (one cache miss per hit, not two).
    triangles: Arc<Vec<TriangleRecord>>,
    /// The scene's distinct surface records, indexed by [`TriangleRecord::surface`].
    surfaces: Arc<Vec<Surface>>,
    patterns: Vec<ScanPattern>,
    measurements: Vec<Measurement>,
    /// Per sensor, the weather's threshold, medium and return mode (none without weather or with
    /// `ideal`).
    weather: Vec<Option<crate::effects::weather::SensorWeather>>,
    vehicle_from_sensor: Vec<Affine3A>,
    layout: RigLayout,
    /// `row_source[merged_row] = (sensor, ring)`.
    row_source: Vec<(usize, usize)>,
    /// `sensor_col_of[sensor][merged_col]`: the sensor column in a merged column, or [`NO_COLUMN`].
    sensor_col_of: Vec<Vec<u32>>,
    /// Each sensor's distinct shot times.
    shot_times: Vec<ShotTimes>,
    /// For a standing vehicle, every merged row's beams and rays (the same in every frame), built once.
    static_beams: Option<Vec<RowBeams>>,
    /// For a standing vehicle and a caster that takes whole frames: the rays of every row in order,
    /// and the key under which the caster keeps them ([`Caster::cast_all_resident`]).
    static_ray_set: Option<(u64, Vec<Ray>)>,
    /// For a moving vehicle and a caster that takes whole frames: every row's beams in the sensor
    /// frame, cast from each frame's shot poses ([`Caster::cast_beams`]: rays made on the device).
    beam_set: Option<rays::DeviceBeams>,
    planes: usize,
    track: PoseTrack,
    frame_period_s: f64,
    config: ScanConfig,
}

/// What scanning a scene needs of it regardless of the rig: the caster's acceleration structure
/// and the per-triangle records. Built once and shared by many [`Scanner`]s
/// ([`Scanner::with_prepared`]), e.g. a sweep over many mounts of one scene.
#[derive(Clone)]
pub struct PreparedScene {
    backend: Backend,
    triangle_count: usize,
    caster: Arc<dyn Caster>,
    triangles: Arc<Vec<TriangleRecord>>,
    surfaces: Arc<Vec<Surface>>,
}

impl PreparedScene {
    /// Builds `backend`'s acceleration structure and the triangle records of `mesh` (fails only for
    /// a GPU backend that cannot start).
    pub fn new(mesh: &SceneMesh, backend: Backend) -> Result<Self> {
        let (triangles, surfaces) = triangle_records(mesh);
        Ok(Self {
            backend,
            triangle_count: mesh.len(),
            caster: Arc::from(backend.build(mesh)?),
            triangles: Arc::new(triangles),
            surfaces: Arc::new(surfaces),
        })
    }
}

/// Casts all frames of a scan and returns them (for small scans; large ones use [`Scanner`] frame by frame).
pub fn scan(mesh: &SceneMesh, rig: &Rig, config: &ScanConfig) -> Result<Vec<Frame>> {
    let scanner = Scanner::new(mesh, rig, config.clone())?;
    Ok((0..config.frames).map(|k| scanner.frame(k)).collect())
}

impl<'a> Scanner<'a> {
    /// Validates the inputs, builds the caster and the rig layout, and settles the ego trajectory.
    pub fn new(mesh: &'a SceneMesh, rig: &'a Rig, config: ScanConfig) -> Result<Self> {
        config.validate()?;
        rig.validate()?;
        mesh.validate().map_err(|m| SimError::invalid("scene mesh", m, "finite vertices, valid indices"))?;
        let prepared = PreparedScene::new(mesh, config.backend)?;
        Self::with_prepared(mesh, rig, config, &prepared)
    }

    /// Like [`Scanner::new`] with the scene's caster and triangle records taken from `prepared`
    /// (built from the same `mesh` with `config.backend`) instead of building them.
    pub fn with_prepared(
        mesh: &'a SceneMesh,
        rig: &'a Rig,
        config: ScanConfig,
        prepared: &PreparedScene,
    ) -> Result<Self> {
        config.validate()?;
        rig.validate()?;
        if prepared.triangle_count != mesh.len() || prepared.backend != config.backend {
            return Err(SimError::invalid(
                "prepared scene",
                format!("{} triangles, {}", prepared.triangle_count, prepared.backend.name()),
                format!("built from this mesh ({} triangles) with {}", mesh.len(), config.backend.name()),
            ));
        }
        let caster = Arc::clone(&prepared.caster);
        let (triangles, surfaces) = (Arc::clone(&prepared.triangles), Arc::clone(&prepared.surfaces));
        let patterns: Vec<ScanPattern> = rig.sensors.iter().map(|s| s.spec.pattern()).collect();
        let shot_times = patterns.iter().map(ShotTimes::new).collect();
        let measurements: Vec<Measurement> = rig
            .sensors
            .iter()
            .map(|s| if config.ideal { s.spec.measurement().ideal() } else { s.spec.measurement() })
            .collect();
        let weather = rig
            .sensors
            .iter()
            .zip(&measurements)
            .map(|(sensor, m)| {
                use crate::effects::weather::{SensorWeather, return_mode_of};
                config
                    .weather
                    .filter(|_| !config.ideal)
                    .map(|w| SensorWeather::new(&w, m).with_return_mode(return_mode_of(&sensor.spec, m)))
            })
            .collect();
        let vehicle_from_sensor = rig.sensors.iter().map(|s| s.mount.vehicle_from_sensor()).collect();
        let layout = RigLayout::new(rig, &patterns);
        let mut row_source = vec![(0, 0); layout.rows];
        for (s, rows) in layout.row_of.iter().enumerate() {
            for (r, &m) in rows.iter().enumerate() {
                row_source[m] = (s, r);
            }
        }
        let sensor_col_of = (0..rig.sensors.len()).map(|s| layout.sensor_col_of(s)).collect();
        let planes = measurements.iter().map(|m| usize::from(m.max_echoes.max(1))).max().unwrap_or(1);
        let frame_period_s = patterns.iter().map(|p| p.frame_period_s).fold(0.0, f64::max);
        let trajectory = Trajectory {
            speed_m_per_s: f64::from(config.speed_m_per_s),
            yaw_rate_rad_per_s: f64::from(config.yaw_rate_rad_per_s),
            waypoints_m: config.waypoints_m.clone(),
        };
        let track =
            PoseTrack::new(caster.as_ref(), trajectory, frame_period_s, config.frames, f64::from(config.ego_z_m));
        let mut scanner = Self {
            mesh,
            caster,
            triangles,
            surfaces,
            patterns,
            measurements,
            weather,
            vehicle_from_sensor,
            layout,
            row_source,
            sensor_col_of,
            planes,
            track,
            frame_period_s,
            config,
            static_beams: None,
            static_ray_set: None,
            beam_set: None,
            shot_times,
        };
        if scanner.track.is_static() {
            let cached: Vec<RowBeams> = (0..scanner.layout.rows)
                .map(|row| {
                    let mut beams = RowBeams::default();
                    scanner.fill_row_beams(0, row, &mut beams, &[]);
                    beams
                })
                .collect();
            if scanner.caster.prefers_frames() {
                let rays = cached.iter().flat_map(|b: &RowBeams| b.rays.iter().copied()).collect();
                scanner.static_ray_set = Some((crate::cast::new_ray_set_key(), rays));
            }
            scanner.static_beams = Some(cached);
        } else if scanner.caster.prefers_frames() {
            scanner.beam_set = scanner.device_beams();
        }
        Ok(scanner)
    }

    /// The scene being scanned.
    pub fn mesh(&self) -> &'a SceneMesh {
        self.mesh
    }

    /// The rig's merged grid layout.
    pub fn layout(&self) -> &RigLayout {
        &self.layout
    }

    /// The firing pattern of each sensor.
    pub fn patterns(&self) -> &[ScanPattern] {
        &self.patterns
    }

    /// The measurement model in force for each sensor (ideal if the scan is ideal).
    pub fn measurements(&self) -> &[Measurement] {
        &self.measurements
    }

    /// Frame period of the rig (the longest sensor period), seconds.
    pub fn frame_period_s(&self) -> f64 {
        self.frame_period_s
    }

    /// Echo planes of every frame's cloud.
    pub fn planes(&self) -> usize {
        self.planes
    }

    /// The caster in use.
    pub fn caster(&self) -> &dyn Caster {
        self.caster.as_ref()
    }

    /// Scans frame `index` into a new cloud.
    pub fn frame(&self, index: usize) -> Frame {
        self.frame_with(index, None)
    }

    /// [`Scanner::frame`] with the hits cast ahead when `ahead` is given.
    fn frame_with(&self, index: usize, ahead: Option<CastAhead>) -> Frame {
        let mut cloud = OrderedCloud::default();
        self.frame_into_with(index, &mut cloud, ahead);
        let vehicle_pose = self.track.frame_start(index);
        Frame {
            index,
            start_time_s: index as f64 * self.frame_period_s,
            vehicle_pose,
            world_from_vehicle: vehicle_pose.world_from_vehicle(),
            cloud,
        }
    }

    /// The vehicle pose at the start of frame `index`.
    pub fn frame_start_pose(&self, index: usize) -> VehiclePose {
        self.track.frame_start(index)
    }

    /// Scans frame `index` into `cloud`, reusing its buffers when its shape fits (loops over many
    /// frames avoid reallocating and page-faulting 14 MB per 128 x 2048 frame). Every plane-0 cell is
    /// written exactly once per frame (a return or the no-return defaults), so a reused cloud needs
    /// no separate reset pass.
    pub fn frame_into(&self, index: usize, cloud: &mut OrderedCloud) {
        self.frame_into_with(index, cloud, None);
    }

    /// [`Scanner::frame_into`], with the frame's shot poses and hits already cast when `ahead` is
    /// given ([`Scanner::scan_frames`]).
    fn frame_into_with(&self, index: usize, cloud: &mut OrderedCloud, ahead: Option<CastAhead>) {
        use rayon::prelude::*;
        let (rows, cols, planes) = (self.layout.rows, self.layout.cols, self.planes);
        let fresh = (cloud.rows, cloud.cols, cloud.planes) != (rows, cols, planes) || cloud.check_consistent().is_err();
        if fresh {
            *cloud = OrderedCloud::empty(rows, cols, planes);
        } else if planes > 1 {
            cloud.reset_cells(rows * cols..cloud.len());
        }
        let start_time_s = index as f64 * self.frame_period_s;
        let shot_poses = self.shot_poses(index);
        let hits = ahead.map(|a| a.hits);
        let extra: Vec<Vec<ExtraEcho>> = if cols == 0 {
            Vec::new()
        } else {
            // Scratch buffers are reused across the rows one worker scans; they never carry data
            // from one row to the next (each row overwrites what it reads), so the output does not
            // depend on how rows are split among threads.
            if self.caster.prefers_frames() {
                let extra = self.scan_frame_at_once(index, start_time_s, cloud, &shot_poses, hits);
                return self.finish_frame(cloud, extra);
            }
            row_views(cloud)
                .into_par_iter()
                .enumerate()
                .map_init(RowScratch::default, |scratch, (row, mut view)| {
                    self.scan_row(index, start_time_s, row, &mut view, scratch, &shot_poses)
                })
                .collect()
        };
        self.finish_frame(cloud, extra);
    }

    /// Writes the second and later echoes of a frame into `cloud`.
    fn finish_frame(&self, cloud: &mut OrderedCloud, extra: Vec<Vec<ExtraEcho>>) {
        for e in extra.into_iter().flatten() {
            let i = cloud.index(usize::from(e.echo), e.row, e.col);
            e.cell.write(cloud, i, e.echo);
        }
    }

    /// Number of merged rows of every frame.
    pub fn rows(&self) -> usize {
        self.layout.rows
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_prepared_scene_scans_like_a_fresh_one_and_must_match_the_mesh() {
        let mesh = crate::scene::builtin::builtin("flat-objects").unwrap();
        let rig = Rig::preset("lux-roof-4").unwrap();
        let config = ScanConfig { seed: 3, ..Default::default() };
        let fresh = Scanner::new(&mesh, &rig, config.clone()).unwrap().frame(0);
        let prepared = PreparedScene::new(&mesh, Backend::Bvh).unwrap();
        let mut moved = rig.clone();
        moved.sensors[0].mount.z_m += 0.3;
        let shared = Scanner::with_prepared(&mesh, &rig, config.clone(), &prepared).unwrap().frame(0);
        // Debug text: no-return cells hold NaN, which `==` never equals.
        let same = |a: &OrderedCloud, b: &OrderedCloud| format!("{a:?}") == format!("{b:?}");
        assert!(same(&fresh.cloud, &shared.cloud));
        assert!(fresh.cloud.returns() > 1000);
        // The same prepared scene serves another rig.
        let other = Scanner::with_prepared(&mesh, &moved, config.clone(), &prepared).unwrap().frame(0);
        assert!(same(&other.cloud, &Scanner::new(&mesh, &moved, config.clone()).unwrap().frame(0).cloud));
        assert!(!same(&other.cloud, &fresh.cloud));
        // Another mesh or backend is refused.
        let flat = crate::scene::builtin::builtin("flat").unwrap();
        assert!(Scanner::with_prepared(&flat, &rig, config.clone(), &prepared).is_err());
        let parry = ScanConfig { backend: Backend::Parry, ..config };
        assert!(Scanner::with_prepared(&mesh, &rig, parry, &prepared).is_err());
    }
}
