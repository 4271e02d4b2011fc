//! Casting and measuring one merged row (or a whole frame at once for casters that prefer it):
//! hits become returns through the measurement effects and are written to the row's cells.

use glam::Vec3;

use super::Scanner;
use super::cells::{Cell, ExtraEcho, RowView, row_views};
use super::rays::{NO_BEAM, RowBeams, ShotPose};
use crate::cast::{Hit, Ray};
use crate::cloud::OrderedCloud;
use crate::effects::measure;
use crate::effects::weather::BeamOutcome;
use crate::layout::NO_COLUMN;
use crate::noise::{BeamKey, Purpose, RowKey};
use crate::scene::{SceneMesh, Surface};

impl Scanner<'_> {
    /// columns, each either a sensor column with its return, a sensor column without one, or a
    /// column the row's sensor does not cover); returns second and later echoes.
    pub(super) fn scan_row(
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
    pub(super) fn scan_frame_at_once(
        &self,
        frame: usize,
        start_time_s: f64,
        cloud: &mut OrderedCloud,
        shot_poses: &[Vec<ShotPose>],
        cast_ahead: Option<Vec<Option<Hit>>>,
    ) -> Vec<Vec<ExtraEcho>> {
        use rayon::prelude::*;
        let build = || -> Vec<RowBeams> {
            (0..self.layout.rows)
                .into_par_iter()
                .map(|row| {
                    let mut beams = RowBeams::default();
                    self.fill_row_beams(frame, row, &mut beams, shot_poses);
                    beams
                })
                .collect()
        };
        let built: Vec<RowBeams>;
        let (beams, hits) = match (&self.static_beams, &self.static_ray_set, &self.beam_set, cast_ahead) {
            (Some(cached), Some((key, rays)), _, _) => (cached.as_slice(), self.caster.cast_all_resident(*key, rays)),
            // Hits cast ahead by the pipeline (`Scanner::scan_frames`): the rows' rays are still made
            // here, for measuring.
            (_, _, _, Some(hits)) => {
                built = build();
                (built.as_slice(), hits)
            }
            // Rays made on the device while the host makes the same rays for measuring.
            (_, _, Some(beams), None) => {
                let poses = self.device_poses(beams, frame);
                let (rows, hits) = rayon::join(build, || self.caster.cast_beams(&beams.set, &poses));
                built = rows;
                (built.as_slice(), hits)
            }
            _ => {
                built = build();
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
    pub(super) fn measure_row(
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
        // Rain and snow: the row's candidate beams for a particle (the others draw nothing).
        let mut candidates = Vec::new();
        if let Some(w) = &self.weather[s] {
            w.row_candidates(&row_key, pattern.cols, &mut candidates);
        }
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
            // This beam's later echoes are `extra[beam_extra..]`, planes 1, 2, ...
            let beam_extra = extra.len();
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
            // Weather: the medium attenuates the return and may replace it with its own, or (dual
            // return) put its own in front of it.
            let first = match &self.weather[s] {
                None => first,
                Some(w) => {
                    let key = BeamKey {
                        seed: self.config.seed,
                        frame: frame as u32,
                        sensor: s as u32,
                        ring: ring as u32,
                        column: c as u32,
                    };
                    let candidate = candidates.get(c).copied().unwrap_or(false);
                    let echoes =
                        w.echoes_in_row(first.as_ref().map(|cell| (cell.range_m, cell.intensity)), &key, candidate);
                    match echoes.first {
                        BeamOutcome::Target { intensity } => first.map(|cell| Cell { intensity, ..cell }),
                        BeamOutcome::Medium { range_m, intensity, class } => {
                            if let (Some(intensity), Some(cell)) = (echoes.target_behind, first) {
                                let target = ExtraEcho { row, col: mc, echo: 1, cell: Cell { intensity, ..cell } };
                                push_behind_medium(&mut extra, beam_extra, target, m.max_echoes);
                            }
                            let point_in_sensor = f.origin_in_sensor + f.dir_in_sensor * range_m;
                            Some(Cell {
                                point_in_vehicle: vehicle_from_sensor.transform_point3(point_in_sensor),
                                range_m,
                                intensity,
                                class,
                                instance: 0,
                                // Facing the sensor.
                                normal: -vehicle_from_sensor.transform_vector3(f.dir_in_sensor),
                                sensor: s as u8,
                                ring: ring as u16,
                                column: c as u32,
                                time_s: start_time_s + f.time_s,
                            })
                        }
                        BeamOutcome::Lost => None,
                    }
                }
            };
            match first {
                Some(cell) => view.set_return(mc, &cell),
                None => view.set_no_return(mc),
            }
        }
        extra
    }
}

/// Dual return with the medium's echo in plane 0: the target's echo `target` (plane 1) goes in
/// front of the beam's later echoes `extra[from..]`, which move back one plane; those beyond the
/// sensor's `planes` are dropped (nearest first, at most `planes` echoes).
fn push_behind_medium(extra: &mut Vec<ExtraEcho>, from: usize, target: ExtraEcho, planes: u8) {
    extra.insert(from, target);
    for e in &mut extra[from + 1..] {
        e.echo += 1;
    }
    // The beam's echoes are last in `extra`, their planes ascending.
    while extra.len() > from && extra.last().is_some_and(|e| e.echo >= planes) {
        extra.pop();
    }
}

/// What the effects need of a triangle that was hit, in 16 bytes (four to a cache line: the hit
/// triangles of a frame are scattered over the mesh, so these loads mostly miss the cache).
#[derive(Clone, Copy, Debug)]
pub(super) struct TriangleRecord {
    /// Unit normal, world frame (front side).
    pub(super) normal_in_world: Vec3,
    /// Index of the triangle's surface record in the table of distinct surfaces.
    pub(super) surface: u32,
}

/// Every triangle's record and the table of the scene's distinct surfaces (scenes have few: one
/// per class and object instance).
pub(super) fn triangle_records(mesh: &SceneMesh) -> (Vec<TriangleRecord>, Vec<Surface>) {
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

/// Per-worker buffers for scanning one row, reused from row to row (see [`Scanner::frame_into`]).
#[derive(Default)]
pub(super) struct RowScratch {
    /// The row's beams when they are not cached (moving vehicle).
    pub(super) beams: RowBeams,
    /// Hit of each ray.
    pub(super) hits: Vec<Option<Hit>>,
    /// Echoes of one multi-echo beam.
    pub(super) echoes: Vec<(f32, Hit, u32)>,
}

/// Groups sub-beam hits (sorted by distance) into echoes at least `separation_m` apart; keeps the
/// nearest hit of each group and counts the sub-beams in it.
pub(super) fn merge_echoes(echoes: &mut Vec<(f32, Hit, u32)>, separation_m: f32) {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::SemanticClass;

    fn echo(col: usize, echo: u8, range_m: f32) -> ExtraEcho {
        let cell = Cell {
            point_in_vehicle: Vec3::X * range_m,
            range_m,
            intensity: 0.5,
            class: SemanticClass(40),
            instance: 0,
            normal: Vec3::NEG_X,
            sensor: 0,
            ring: 0,
            column: col as u32,
            time_s: 0.0,
        };
        ExtraEcho { row: 0, col, echo, cell }
    }

    fn planes_and_ranges(extra: &[ExtraEcho]) -> Vec<(usize, u8, f32)> {
        extra.iter().map(|e| (e.col, e.echo, e.cell.range_m)).collect()
    }

    /// Dual with the medium's echo in plane 0: the surface goes to plane 1 and the beam's later
    /// echoes move back one plane, those beyond the sensor's planes dropped; other beams' echoes
    /// stay as they are.
    #[test]
    fn the_surface_goes_behind_the_medium_and_later_echoes_move_back() {
        // Column 3's second echo, then column 4's (the beam in hand) echoes 1 and 2.
        let beam = || vec![echo(3, 1, 9.0), echo(4, 1, 20.0), echo(4, 2, 30.0)];
        let surface = echo(4, 1, 12.0);
        // Three planes (the LUX): surface, then the old planes 1 and 2 as 2 and 3; 3 is dropped.
        let mut extra = beam();
        push_behind_medium(&mut extra, 1, surface, 3);
        assert_eq!(planes_and_ranges(&extra), vec![(3, 1, 9.0), (4, 1, 12.0), (4, 2, 20.0)]);
        // Two planes (dual): the surface only.
        let mut extra = beam();
        push_behind_medium(&mut extra, 1, surface, 2);
        assert_eq!(planes_and_ranges(&extra), vec![(3, 1, 9.0), (4, 1, 12.0)]);
        // A beam without later echoes.
        let mut extra = vec![echo(3, 1, 9.0)];
        push_behind_medium(&mut extra, 1, surface, 2);
        assert_eq!(planes_and_ranges(&extra), vec![(3, 1, 9.0), (4, 1, 12.0)]);
    }
}
