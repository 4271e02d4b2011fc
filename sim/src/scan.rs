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

use glam::{Affine3A, Vec3};

use crate::cast::{Backend, Caster, Hit, Ray};
use crate::cloud::OrderedCloud;
use crate::effects::{cast_limit_m, measure};
use crate::error::{Result, SimError, check_range};
use crate::layout::{NO_COLUMN, RigLayout};
use crate::motion::{PoseTrack, Trajectory, VehiclePose};
use crate::noise::{BeamKey, Purpose, RowKey};
use crate::rig::Rig;
use crate::scene::{SceneMesh, SemanticClass, Surface};
use crate::sensor::{Firing, Measurement, ScanPattern};

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
        let mut cloud = OrderedCloud::default();
        self.frame_into(index, &mut cloud);
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
        let extra: Vec<Vec<ExtraEcho>> = if cols == 0 {
            Vec::new()
        } else {
            // Scratch buffers are reused across the rows one worker scans; they never carry data
            // from one row to the next (each row overwrites what it reads), so the output does not
            // depend on how rows are split among threads.
            if self.caster.prefers_frames() {
                let extra = self.scan_frame_at_once(index, start_time_s, cloud, &shot_poses);
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

    /// A moving vehicle's pose in frame `frame` at each distinct shot time of each sensor (indexed
    /// like [`ShotTimes::times`]), computed once per frame: many beams share a shot time (all
    /// lasers of an OS1 column fire together). Empty for a standing vehicle.
    fn shot_poses(&self, frame: usize) -> Vec<Vec<ShotPose>> {
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
    fn fill_row_beams(&self, frame: usize, row: usize, out: &mut RowBeams, shot_poses: &[Vec<ShotPose>]) {
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

    /// Number of merged rows of every frame.
    pub fn rows(&self) -> usize {
        self.layout.rows
    }

    /// Scans one merged row: writes every plane-0 cell of `view` exactly once (walking the merged
    /// columns, each either a sensor column with its return, a sensor column without one, or a
    /// column the row's sensor does not cover); returns second and later echoes.
    fn scan_row(
        &self,
        frame: usize,
        start_time_s: f64,
        row: usize,
        view: &mut RowView<'_>,
        scratch: &mut RowScratch,
        shot_poses: &[Vec<ShotPose>],
    ) -> Vec<ExtraEcho> {
        let RowScratch { beams, hits, echoes } = scratch;
        let beams = match &self.static_beams {
            Some(cached) => &cached[row],
            None => {
                self.fill_row_beams(frame, row, beams, shot_poses);
                beams
            }
        };
        // No clearing: `cast_batch` writes every entry (its contract), so only new entries are filled.
        hits.resize(beams.rays.len(), None);
        self.caster.cast_batch(&beams.rays, hits);
        self.measure_row(frame, start_time_s, row, view, beams, hits, echoes, shot_poses)
    }

    /// Scans a frame whose rays the caster takes all at once ([`Caster::prefers_frames`]): every
    /// row's beams (cached for a standing vehicle, whose rays the caster keeps under
    /// `static_ray_set`), one cast, then every row measured from its hits as [`Scanner::scan_row`]
    /// does, so the cloud is the same.
    fn scan_frame_at_once(
        &self,
        frame: usize,
        start_time_s: f64,
        cloud: &mut OrderedCloud,
        shot_poses: &[Vec<ShotPose>],
    ) -> Vec<Vec<ExtraEcho>> {
        use rayon::prelude::*;
        let built: Vec<RowBeams>;
        let (beams, hits) = match (&self.static_beams, &self.static_ray_set) {
            (Some(cached), Some((key, rays))) => (cached.as_slice(), self.caster.cast_all_resident(*key, rays)),
            _ => {
                built = (0..self.layout.rows)
                    .into_par_iter()
                    .map(|row| {
                        let mut beams = RowBeams::default();
                        self.fill_row_beams(frame, row, &mut beams, shot_poses);
                        beams
                    })
                    .collect();
                let rays: Vec<Ray> = built.iter().flat_map(|b| b.rays.iter().copied()).collect();
                (built.as_slice(), self.caster.cast_all(&rays))
            }
        };
        let mut first = Vec::with_capacity(beams.len() + 1);
        first.push(0);
        for b in beams {
            first.push(first.last().copied().unwrap_or(0) + b.rays.len());
        }
        row_views(cloud)
            .into_par_iter()
            .enumerate()
            .map_init(Vec::new, |echoes, (row, mut view)| {
                let hits = &hits[first[row]..first[row + 1]];
                self.measure_row(frame, start_time_s, row, &mut view, &beams[row], hits, echoes, shot_poses)
            })
            .collect()
    }

    /// Writes every plane-0 cell of merged row `row` from its beams and their hits (see
    /// [`Scanner::scan_row`]); returns second and later echoes.
    #[allow(clippy::too_many_arguments)]
    fn measure_row(
        &self,
        frame: usize,
        start_time_s: f64,
        row: usize,
        view: &mut RowView<'_>,
        beams: &RowBeams,
        hits: &[Option<Hit>],
        echoes: &mut Vec<(f32, Hit, u32)>,
        shot_poses: &[Vec<ShotPose>],
    ) -> Vec<ExtraEcho> {
        let (s, ring) = self.row_source[row];
        let pattern = &self.patterns[s];
        // A local copy: its fields are loop invariants the compiler can hoist (through a reference it
        // must assume the cell writes may change them).
        let m = &{ self.measurements[s] };
        let vehicle_from_sensor = self.vehicle_from_sensor[s];
        let RowBeams { rays, beam_shot, beam_of_col, sub_rays, static_pose: static_world_from_sensor, beam_col } =
            beams;
        let (sub_rays, static_world_from_sensor) = (*sub_rays, *static_world_from_sensor);

        let firings = &pattern.firings[ring * pattern.cols..(ring + 1) * pattern.cols];
        let mut extra = Vec::new();
        let static_vehicle_from_world = ShotPose::new(static_world_from_sensor, vehicle_from_sensor).vehicle_from_world;
        let row_key = RowKey { seed: self.config.seed, frame: frame as u32, sensor: s as u32, ring: ring as u32 };
        // The row stream's draws for columns 0 ..= the last column with a hit: a prefix of the full
        // row stream, so the same numbers as drawing all columns (rows that hit nothing, e.g. beams
        // pointing at the sky, draw nothing).
        let noise = match hits.iter().rposition(Option::is_some) {
            Some(last) if m.range_sigma_m > 0.0 => {
                row_key.normals(Purpose::RangeNoise, beam_col[last / sub_rays] as usize + 1)
            }
            _ => Vec::new(),
        };
        for (mc, &c) in self.sensor_col_of[s].iter().enumerate() {
            view.ring[mc] = ring as u16;
            if c == NO_COLUMN {
                view.sensor[mc] = u8::MAX;
                view.column[mc] = 0;
                view.time[mc] = 0.0;
                view.set_no_return(mc);
                continue;
            }
            let c = c as usize;
            view.sensor[mc] = s as u8;
            view.column[mc] = c as u32;
            let b = beam_of_col[c] as usize;
            let Some(f) = firings[c].as_ref().filter(|_| b != NO_BEAM as usize) else {
                view.time[mc] = start_time_s + 0.0;
                view.set_no_return(mc);
                continue;
            };
            view.time[mc] = start_time_s + f.time_s;
            let centre_dir = rays[b * sub_rays].dir;
            let vehicle_from_world =
                beam_shot.get(b).map_or(static_vehicle_from_world, |&k| shot_poses[s][k as usize].vehicle_from_world);
            // The cell of a hit of this beam reported as echo `echo` by `count` of its sub-rays, or
            // `None` when the sensor reports nothing.
            let hit_cell = |hit: Hit, count: u32, echo: u8| {
                let TriangleRecord { normal_in_world: mut n_world, surface } = self.triangles[hit.triangle as usize];
                let surface = self.surfaces[surface as usize];
                if n_world.dot(centre_dir) > 0.0 {
                    n_world = -n_world;
                }
                let cos_inc = -n_world.dot(centre_dir);
                // First echoes use the row stream; later echoes (rare) their own keyed stream.
                let z = match (echo, noise.get(c)) {
                    (0, Some(&z)) => z,
                    (0, None) => 0.0,
                    _ => BeamKey {
                        seed: self.config.seed,
                        frame: frame as u32,
                        sensor: s as u32,
                        ring: ring as u32,
                        column: c as u32 | (u32::from(echo) << 24),
                    }
                    .normal(Purpose::RangeNoise),
                };
                let meas = measure(m, hit.t, cos_inc, surface.reflectivity, z)?;
                let point_in_sensor = f.origin_in_sensor + f.dir_in_sensor * meas.range_m;
                Some(Cell {
                    point_in_vehicle: vehicle_from_sensor.transform_point3(point_in_sensor),
                    range_m: meas.range_m,
                    // (Exact when one sub-ray: x * 1 / 1 == x.)
                    intensity: if sub_rays == 1 {
                        meas.intensity
                    } else {
                        meas.intensity * count as f32 / sub_rays as f32
                    },
                    class: surface.class,
                    instance: surface.instance,
                    normal: Vec3::from(vehicle_from_world * glam::Vec3A::from(n_world)),
                    sensor: s as u8,
                    ring: ring as u16,
                    column: c as u32,
                    time_s: start_time_s + f.time_s,
                })
            };
            let first = if sub_rays == 1 {
                // One ray per beam: at most one echo.
                hits[b].filter(|_| m.max_echoes > 0).and_then(|h| hit_cell(h, 1, 0))
            } else {
                echoes.clear();
                echoes.extend(hits[b * sub_rays..(b + 1) * sub_rays].iter().flatten().map(|h| (h.t, *h, 1)));
                merge_echoes(echoes, m.echo_separation_m);
                let mut first = None;
                let mut echo = 0u8;
                for &(_, hit, count) in echoes.iter() {
                    if echo >= m.max_echoes {
                        break;
                    }
                    let Some(cell) = hit_cell(hit, count, echo) else { continue };
                    if echo == 0 {
                        first = Some(cell);
                    } else {
                        extra.push(ExtraEcho { row, col: mc, echo, cell });
                    }
                    echo += 1;
                }
                first
            };
            match first {
                Some(cell) => {
                    view.point[mc] = cell.point_in_vehicle;
                    view.range[mc] = cell.range_m;
                    view.intensity[mc] = cell.intensity;
                    view.label[mc] = cell.class;
                    view.instance[mc] = cell.instance;
                    view.ground[mc] = cell.class.is_ground();
                    view.normal[mc] = cell.normal;
                }
                None => view.set_no_return(mc),
            }
        }
        extra
    }
}

/// What the effects need of a triangle that was hit, in 16 bytes (four to a cache line: the hit
/// triangles of a frame are scattered over the mesh, so these loads mostly miss the cache).
#[derive(Clone, Copy, Debug)]
struct TriangleRecord {
    /// Unit normal, world frame (front side).
    normal_in_world: Vec3,
    /// Index of the triangle's surface record in the table of distinct surfaces.
    surface: u32,
}

/// Every triangle's record and the table of the scene's distinct surfaces (scenes have few: one
/// per class and object instance).
fn triangle_records(mesh: &SceneMesh) -> (Vec<TriangleRecord>, Vec<Surface>) {
    let mut surfaces: Vec<Surface> = Vec::new();
    let mut index_of: std::collections::HashMap<(u16, u32, u32), u32> = std::collections::HashMap::new();
    let records = (0..mesh.len())
        .map(|i| {
            let sf = mesh.surfaces[i];
            let surface = *index_of.entry((sf.class.0, sf.instance, sf.reflectivity.to_bits())).or_insert_with(|| {
                surfaces.push(sf);
                (surfaces.len() - 1) as u32
            });
            TriangleRecord { normal_in_world: mesh.triangle_normal(i), surface }
        })
        .collect();
    (records, surfaces)
}

/// The sensor pose at one shot.
#[derive(Clone, Copy, Debug)]
struct ShotPose {
    /// Sensor pose in the world at the shot.
    world_from_sensor: Affine3A,
    /// Rotation taking world vectors to the vehicle frame at the shot:
    /// `vehicle_from_sensor * transpose(world_from_sensor)`.
    vehicle_from_world: glam::Mat3A,
}

impl ShotPose {
    fn new(world_from_sensor: Affine3A, vehicle_from_sensor: Affine3A) -> Self {
        Self {
            world_from_sensor,
            vehicle_from_world: vehicle_from_sensor.matrix3 * world_from_sensor.matrix3.transpose(),
        }
    }
}

/// A sensor's distinct shot times (seconds after the frame start) and which one each firing uses.
struct ShotTimes {
    /// Distinct shot times, increasing.
    times: Vec<f64>,
    /// Per pattern cell (row-major), the index of its shot time in `times` (0 where it does not fire).
    index: Vec<u32>,
}

impl ShotTimes {
    fn new(pattern: &ScanPattern) -> Self {
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

/// Marks an unfired sensor column in [`RowScratch::beam_of_col`].
const NO_BEAM: u32 = u32::MAX;

/// The beams of one merged row and their rays (see [`Scanner::row_rays`]).
#[derive(Clone, Debug, Default)]
struct RowBeams {
    /// The row's rays, `sub_rays` per fired beam.
    rays: Vec<Ray>,
    /// Rays per beam.
    sub_rays: usize,
    /// Sensor column of each fired beam.
    beam_col: Vec<u32>,
    /// Shot-time index ([`ShotTimes::times`]) of each fired beam (moving vehicle only, else empty).
    beam_shot: Vec<u32>,
    /// `world_from_sensor` at the start of the frame: the pose of every beam of a standing vehicle.
    static_pose: Affine3A,
    /// Beam index of each sensor column, [`NO_BEAM`] where the sensor does not fire.
    beam_of_col: Vec<u32>,
}

/// Per-worker buffers for scanning one row, reused from row to row (see [`Scanner::frame_into`]).
#[derive(Default)]
struct RowScratch {
    /// The row's beams when they are not cached (moving vehicle).
    beams: RowBeams,
    /// Hit of each ray.
    hits: Vec<Option<Hit>>,
    /// Echoes of one multi-echo beam.
    echoes: Vec<(f32, Hit, u32)>,
}

/// Groups sub-beam hits (sorted by distance) into echoes at least `separation_m` apart; keeps the
/// nearest hit of each group and counts the sub-beams in it.
fn merge_echoes(echoes: &mut Vec<(f32, Hit, u32)>, separation_m: f32) {
    echoes.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut out: Vec<(f32, Hit, u32)> = Vec::with_capacity(echoes.len());
    for &e in echoes.iter() {
        match out.last_mut() {
            Some(last) if e.0 - last.0 < separation_m => last.2 += 1,
            _ => out.push(e),
        }
    }
    *echoes = out;
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

/// A return's fields, for writing a cell of a later echo plane.
#[derive(Clone, Copy, Debug)]
struct Cell {
    point_in_vehicle: Vec3,
    range_m: f32,
    intensity: f32,
    class: SemanticClass,
    instance: u32,
    normal: Vec3,
    sensor: u8,
    ring: u16,
    column: u32,
    time_s: f64,
}

impl Cell {
    fn write(&self, cloud: &mut OrderedCloud, i: usize, echo: u8) {
        cloud.point_in_vehicle[i] = self.point_in_vehicle;
        cloud.range_m[i] = self.range_m;
        cloud.intensity[i] = self.intensity;
        cloud.label[i] = self.class;
        cloud.instance[i] = self.instance;
        cloud.ground[i] = self.class.is_ground();
        cloud.normal[i] = self.normal;
        cloud.sensor[i] = self.sensor;
        cloud.ring[i] = self.ring;
        cloud.column[i] = self.column;
        cloud.time_s[i] = self.time_s;
        cloud.echo[i] = echo;
    }
}

/// A second or later echo, written after the parallel row pass.
#[derive(Clone, Copy, Debug)]
struct ExtraEcho {
    row: usize,
    col: usize,
    echo: u8,
    cell: Cell,
}

/// Mutable views of one plane-0 row of every field of a cloud.
struct RowView<'c> {
    point: &'c mut [Vec3],
    range: &'c mut [f32],
    intensity: &'c mut [f32],
    ring: &'c mut [u16],
    column: &'c mut [u32],
    sensor: &'c mut [u8],
    time: &'c mut [f64],
    label: &'c mut [SemanticClass],
    instance: &'c mut [u32],
    ground: &'c mut [bool],
    normal: &'c mut [Vec3],
}

impl RowView<'_> {
    /// Writes the no-return defaults of the return fields of cell `i` (as [`OrderedCloud::empty`]
    /// makes them); ring, column, sensor and time are the caller's.
    #[inline]
    fn set_no_return(&mut self, i: usize) {
        self.point[i] = Vec3::NAN;
        self.range[i] = f32::NAN;
        self.intensity[i] = 0.0;
        self.label[i] = SemanticClass::UNLABELED;
        self.instance[i] = 0;
        self.ground[i] = false;
        self.normal[i] = Vec3::ZERO;
    }
}

/// Splits plane 0 of `cloud` into disjoint per-row views (for parallel filling). Requires `cols > 0`.
fn row_views(cloud: &mut OrderedCloud) -> Vec<RowView<'_>> {
    let n = cloud.rows * cloud.cols;
    let cols = cloud.cols;
    let mut point = cloud.point_in_vehicle[..n].chunks_mut(cols);
    let mut range = cloud.range_m[..n].chunks_mut(cols);
    let mut intensity = cloud.intensity[..n].chunks_mut(cols);
    let mut ring = cloud.ring[..n].chunks_mut(cols);
    let mut column = cloud.column[..n].chunks_mut(cols);
    let mut sensor = cloud.sensor[..n].chunks_mut(cols);
    let mut time = cloud.time_s[..n].chunks_mut(cols);
    let mut label = cloud.label[..n].chunks_mut(cols);
    let mut instance = cloud.instance[..n].chunks_mut(cols);
    let mut ground = cloud.ground[..n].chunks_mut(cols);
    let mut normal = cloud.normal[..n].chunks_mut(cols);
    let mut views = Vec::with_capacity(cloud.rows);
    while let (Some(p), Some(r), Some(i), Some(rg), Some(c), Some(s), Some(t), Some(l), Some(inst), Some(g), Some(nm)) = (
        point.next(),
        range.next(),
        intensity.next(),
        ring.next(),
        column.next(),
        sensor.next(),
        time.next(),
        label.next(),
        instance.next(),
        ground.next(),
        normal.next(),
    ) {
        views.push(RowView {
            point: p,
            range: r,
            intensity: i,
            ring: rg,
            column: c,
            sensor: s,
            time: t,
            label: l,
            instance: inst,
            ground: g,
            normal: nm,
        });
    }
    views
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
