//! Rays through the device in batches: two batch slots kept across calls (and frames), the next
//! batch uploaded and run while the previous one is read back, a standing rig's rays kept on the
//! device, and the device's time split by timestamp queries into upload, kernel and readback.

use std::collections::VecDeque;
use std::num::NonZeroU64;
use std::ops::Range;
use std::time::Instant;

use super::device::{Gpu, Timestamps};
use super::scene::SceneBuffers;
use crate::cast::{BeamSet, DeviceStats, Ray};

/// Result triangle of a ray that hit nothing.
pub(super) const MISS: u32 = u32::MAX;
/// Result triangle of a ray whose traversal overflowed the shader's stack (the host casts it on
/// the CPU).
pub(super) const OVERFLOW: u32 = u32::MAX - 1;

/// Rays per dispatch at most (a workgroup of 64 per 64 rays, under the 65,535-workgroup limit).
const MAX_BATCH_RAYS: u64 = 1 << 20;
/// Bytes per ray on the device (two `vec4<f32>`) and per result (`vec2<u32>`).
const RAY_BYTES: u64 = 32;
const HIT_BYTES: u64 = 8;
/// Bytes per beam on the device and per pose (three `vec4<f32>` each).
const BEAM_BYTES: u64 = 48;
const POSE_BYTES: u64 = 48;
/// Bytes of the uniform parameters and of the four timestamps.
const PARAM_BYTES: u64 = 32;
const STAMP_BYTES: u64 = 32;
/// Batches in flight: one read back while the next runs.
const SLOTS: usize = 2;

/// One batch's device buffers, kept across calls and regrown only for a larger batch.
struct Slot {
    capacity: usize,
    rays: wgpu::Buffer,
    hits: wgpu::Buffer,
    params: wgpu::Buffer,
    /// The hits, then the four timestamps.
    readback: wgpu::Buffer,
    bind: wgpu::BindGroup,
    /// Four timestamps: before the upload, before the kernel, after it, after the readback copy.
    queries: Option<(wgpu::QuerySet, wgpu::Buffer)>,
}

impl Slot {
    fn new(gpu: &Gpu, scene: &SceneBuffers, capacity: usize) -> Self {
        let buffer = |label, size: u64, usage| {
            gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage,
                mapped_at_creation: false,
            })
        };
        use wgpu::BufferUsages as U;
        let n = capacity as u64;
        let rays = buffer("rays", n * RAY_BYTES, U::STORAGE | U::COPY_DST);
        let hits = buffer("hits", n * HIT_BYTES, U::STORAGE | U::COPY_SRC);
        let params = buffer("params", PARAM_BYTES, U::UNIFORM | U::COPY_DST);
        let readback = buffer("readback", n * HIT_BYTES + STAMP_BYTES, U::MAP_READ | U::COPY_DST);
        let mut entries = scene.entries();
        entries.push(wgpu::BindGroupEntry { binding: 6, resource: rays.as_entire_binding() });
        entries.push(wgpu::BindGroupEntry { binding: 7, resource: hits.as_entire_binding() });
        entries.push(wgpu::BindGroupEntry { binding: 8, resource: params.as_entire_binding() });
        let bind = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("caster"),
            layout: &gpu.layout,
            entries: &entries,
        });
        let queries = (gpu.timestamps != Timestamps::None).then(|| {
            let set = gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("cast timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: 4,
            });
            (set, buffer("timestamps", STAMP_BYTES, U::QUERY_RESOLVE | U::COPY_SRC))
        });
        Self { capacity, rays, hits, params, readback, bind, queries }
    }

    /// A bind group like the slot's own with `input` (a beam set and its poses) at binding 6.
    fn bind_with(&self, gpu: &Gpu, scene: &SceneBuffers, input: &wgpu::Buffer) -> wgpu::BindGroup {
        let mut entries = scene.entries();
        entries.push(wgpu::BindGroupEntry { binding: 6, resource: input.as_entire_binding() });
        entries.push(wgpu::BindGroupEntry { binding: 7, resource: self.hits.as_entire_binding() });
        entries.push(wgpu::BindGroupEntry { binding: 8, resource: self.params.as_entire_binding() });
        gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("caster (beams)"),
            layout: &gpu.layout,
            entries: &entries,
        })
    }
}

/// A beam set kept on the device: the beams, then room for the poses of `frames` frames.
struct BeamInput {
    key: u64,
    buffer: wgpu::Buffer,
    /// Frames whose poses fit after the beams.
    frames: usize,
}

/// What a call's batches read.
enum Input<'a> {
    /// Rays made on the host, uploaded batch by batch.
    Rays(&'a [Ray]),
    /// Rays kept on the device, a buffer per batch.
    Resident(&'a [wgpu::Buffer]),
    /// Rays made on the device: one bind group per slot, beams per frame, the first pose's vec4 and
    /// poses per frame.
    Beams { binds: Vec<wgpu::BindGroup>, beams: u32, pose_base: u32, poses: u32 },
}

/// A standing rig's rays kept on the device, one buffer per batch.
struct Resident {
    key: u64,
    len: usize,
    batches: Vec<wgpu::Buffer>,
}

/// The device side of a caster: batch slots, the upload belt, the resident rays and beams, and the
/// counters. Callers take it under a lock: the device's queue runs one stream of batches anyway.
pub(super) struct Stream {
    slots: Vec<Slot>,
    belt: wgpu::util::StagingBelt,
    resident: Option<Resident>,
    beams: Option<BeamInput>,
    pub(super) stats: DeviceStats,
    packed: Vec<f32>,
}

/// A batch submitted and not yet read back.
struct InFlight {
    slot: usize,
    rays: Range<usize>,
    submission: wgpu::SubmissionIndex,
}

impl Stream {
    pub(super) fn new(gpu: &Gpu) -> Self {
        Self {
            slots: Vec::new(),
            belt: wgpu::util::StagingBelt::new(gpu.device.clone(), 4 << 20),
            resident: None,
            beams: None,
            stats: DeviceStats::default(),
            packed: Vec::new(),
        }
    }

    /// Rays per batch on this device: within the storage-binding limit and the dispatch limit.
    fn batch_rays(gpu: &Gpu) -> usize {
        (gpu.max_binding_bytes / RAY_BYTES).clamp(64, MAX_BATCH_RAYS) as usize
    }

    /// Batch slots for batches of `batch` rays (kept when large enough).
    fn ensure_slots(&mut self, gpu: &Gpu, scene: &SceneBuffers, batch: usize) {
        if self.slots.first().is_none_or(|s| s.capacity < batch) {
            self.slots = (0..SLOTS).map(|_| Slot::new(gpu, scene, batch)).collect();
        }
    }

    /// Appends `(t bits, leaf-order triangle or MISS / OVERFLOW)` of every ray to `out`. With a
    /// `resident` key the rays stay on the device: a later call with the same key and as many rays
    /// casts the kept copy without uploading (the caller guarantees the rays are the same).
    pub(super) fn cast(
        &mut self,
        gpu: &Gpu,
        scene: &SceneBuffers,
        rays: &[Ray],
        resident: Option<u64>,
        out: &mut Vec<(u32, u32)>,
    ) {
        if scene.empty || rays.is_empty() {
            out.extend(std::iter::repeat_n((0, MISS), rays.len()));
            return;
        }
        let t0 = Instant::now();
        let batch = Self::batch_rays(gpu).min(rays.len());
        self.ensure_slots(gpu, scene, batch);
        let ranges: Vec<Range<usize>> =
            (0..rays.len()).step_by(batch).map(|a| a..(a + batch).min(rays.len())).collect();
        if let Some(key) = resident
            && self.resident.as_ref().is_none_or(|r| r.key != key || r.len != rays.len())
        {
            self.resident = Some(self.upload_resident(gpu, key, rays, &ranges));
        }
        let kept = resident.and(self.resident.take());
        let input = match &kept {
            Some(r) => Input::Resident(&r.batches),
            None => Input::Rays(rays),
        };
        self.run(gpu, scene, &input, ranges, out);
        if kept.is_some() {
            self.resident = kept;
        }
        self.stats.wall_s += t0.elapsed().as_secs_f64();
    }

    /// Appends the hits of `beams` placed by every frame's poses (frame after frame, beam order)
    /// to `out`, the rays made on the device: the beams go up once per set, the poses per call.
    /// `Err` (nothing appended) when the beams and one frame's poses exceed a binding.
    pub(super) fn cast_beams(
        &mut self,
        gpu: &Gpu,
        scene: &SceneBuffers,
        set: &BeamSet,
        poses: &[glam::Affine3A],
        out: &mut Vec<(u32, u32)>,
    ) -> Result<(), super::GpuError> {
        let (n, per) = (set.beams().len(), set.poses_per_frame());
        let frames = set.frames_in(poses);
        if scene.empty || n == 0 || frames == 0 {
            out.extend(std::iter::repeat_n((0, MISS), n * frames));
            return Ok(());
        }
        let t0 = Instant::now();
        let beam_bytes = n as u64 * BEAM_BYTES;
        let frame_bytes = per as u64 * POSE_BYTES;
        let room = gpu.max_binding_bytes.saturating_sub(beam_bytes) / frame_bytes.max(1);
        if room == 0 {
            return Err(super::GpuError::TooLarge {
                buffer: "beams and one frame's poses",
                needed_bytes: beam_bytes + frame_bytes,
                limit_bytes: gpu.max_binding_bytes,
            });
        }
        // Frames per chunk: all of them, within a binding and 64 MiB of poses.
        let chunk_frames = (frames as u64).min(room).min(((64 << 20) / frame_bytes).max(1)) as usize;
        if self.beams.as_ref().is_none_or(|b| b.key != set.key() || b.frames < chunk_frames) {
            self.beams = Some(self.upload_beams(gpu, set, chunk_frames));
        }
        let Some(kept) = self.beams.take() else { return Ok(()) };
        let batch = Self::batch_rays(gpu).min(n * chunk_frames);
        self.ensure_slots(gpu, scene, batch);
        let binds: Vec<wgpu::BindGroup> = self.slots.iter().map(|s| s.bind_with(gpu, scene, &kept.buffer)).collect();
        let input = Input::Beams { binds, beams: n as u32, pose_base: 3 * n as u32, poses: per as u32 };
        let mut rows = Vec::new();
        for chunk in poses[..frames * per].chunks(chunk_frames * per) {
            rows.clear();
            for m in chunk {
                let (r, t) = (m.matrix3, m.translation);
                rows.extend_from_slice(&[r.x_axis.x, r.y_axis.x, r.z_axis.x, t.x]);
                rows.extend_from_slice(&[r.x_axis.y, r.y_axis.y, r.z_axis.y, t.y]);
                rows.extend_from_slice(&[r.x_axis.z, r.y_axis.z, r.z_axis.z, t.z]);
            }
            // The previous chunk's batches were all read back: its poses are no longer in use.
            gpu.queue.write_buffer(&kept.buffer, beam_bytes, bytemuck::cast_slice(&rows));
            self.stats.upload_bytes += std::mem::size_of_val(rows.as_slice()) as u64;
            let total = n * (chunk.len() / per);
            let ranges = (0..total).step_by(batch).map(|a| a..(a + batch).min(total)).collect();
            self.run(gpu, scene, &input, ranges, out);
        }
        self.beams = Some(kept);
        self.stats.wall_s += t0.elapsed().as_secs_f64();
        Ok(())
    }

    /// Uploads a beam set once, with room for the poses of `frames` frames after it.
    fn upload_beams(&mut self, gpu: &Gpu, set: &BeamSet, frames: usize) -> BeamInput {
        let mut packed = Vec::with_capacity(set.beams().len() * 12);
        for b in set.beams() {
            let (o, d) = (b.origin_in_sensor, b.dir_in_sensor);
            packed.extend_from_slice(&[o.x, o.y, o.z, b.t_max_m.min(f32::MAX), d.x, d.y, d.z, f32::from_bits(b.pose)]);
            packed.extend_from_slice(&[b.pose_blend, b.side_offset, 0.0, 0.0]);
        }
        let size = set.beams().len() as u64 * BEAM_BYTES + (frames * set.poses_per_frame()) as u64 * POSE_BYTES;
        let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("beams and poses"),
            size,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        gpu.queue.write_buffer(&buffer, 0, bytemuck::cast_slice(&packed));
        self.stats.upload_bytes += std::mem::size_of_val(packed.as_slice()) as u64;
        self.stats.resident_uploads += 1;
        BeamInput { key: set.key(), buffer, frames }
    }

    /// Runs the batches `ranges` of `input`, one read back while the next runs, appending their
    /// results to `out`.
    fn run(
        &mut self,
        gpu: &Gpu,
        scene: &SceneBuffers,
        input: &Input<'_>,
        ranges: Vec<Range<usize>>,
        out: &mut Vec<(u32, u32)>,
    ) {
        let Stream { slots, belt, stats, packed, .. } = self;
        let mut in_flight: VecDeque<InFlight> = VecDeque::new();
        for (k, range) in ranges.into_iter().enumerate() {
            if in_flight.len() == SLOTS
                && let Some(done) = in_flight.pop_front()
            {
                read_back(gpu, &slots[done.slot], done, stats, out);
            }
            let slot = &slots[k % SLOTS];
            let m = range.len() as u64;
            let mut encoder =
                gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("cast") });
            let stamp = |encoder: &mut wgpu::CommandEncoder, i: u32| {
                if let (Timestamps::Encoder, Some((set, _))) = (gpu.timestamps, &slot.queries) {
                    encoder.write_timestamp(set, i);
                }
            };
            stamp(&mut encoder, 0);
            let mut params = [m as u32, 0, 0, 0, 0, 0, 0, 0];
            let (pipeline, bind) = match input {
                Input::Resident(batches) => {
                    encoder.copy_buffer_to_buffer(&batches[k], 0, &slot.rays, 0, m * RAY_BYTES);
                    (&scene.pipeline, &slot.bind)
                }
                Input::Rays(rays) => {
                    pack(&rays[range.clone()], packed);
                    let size = NonZeroU64::new(m * RAY_BYTES).expect("a batch has rays");
                    belt.write_buffer(&mut encoder, &slot.rays, 0, size).copy_from_slice(bytemuck::cast_slice(packed));
                    stats.upload_bytes += m * RAY_BYTES;
                    (&scene.pipeline, &slot.bind)
                }
                Input::Beams { binds, beams, pose_base, poses } => {
                    params[1..5].copy_from_slice(&[range.start as u32, *beams, *pose_base, *poses]);
                    (&scene.beam_pipeline, &binds[k % SLOTS])
                }
            };
            belt.write_buffer(&mut encoder, &slot.params, 0, NonZeroU64::new(PARAM_BYTES).expect("32"))
                .copy_from_slice(bytemuck::cast_slice(&params));
            stamp(&mut encoder, 1);
            {
                let timestamp_writes = match (gpu.timestamps, &slot.queries) {
                    (Timestamps::Pass, Some((set, _))) => Some(wgpu::ComputePassTimestampWrites {
                        query_set: set,
                        beginning_of_pass_write_index: Some(1),
                        end_of_pass_write_index: Some(2),
                    }),
                    _ => None,
                };
                let mut pass =
                    encoder.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("cast"), timestamp_writes });
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, bind, &[]);
                pass.dispatch_workgroups((m as u32).div_ceil(64), 1, 1);
            }
            stamp(&mut encoder, 2);
            encoder.copy_buffer_to_buffer(&slot.hits, 0, &slot.readback, 0, m * HIT_BYTES);
            stamp(&mut encoder, 3);
            match (gpu.timestamps, &slot.queries) {
                (Timestamps::Encoder, Some((set, resolve))) => {
                    encoder.resolve_query_set(set, 0..4, resolve, 0);
                    encoder.copy_buffer_to_buffer(resolve, 0, &slot.readback, m * HIT_BYTES, STAMP_BYTES);
                }
                // Only the pass's two timestamps were written: they go to places 1 and 2.
                (Timestamps::Pass, Some((set, resolve))) => {
                    encoder.resolve_query_set(set, 1..3, resolve, 0);
                    encoder.copy_buffer_to_buffer(resolve, 0, &slot.readback, m * HIT_BYTES + 8, 16);
                }
                _ => {}
            }
            belt.finish();
            let submission = gpu.queue.submit(Some(encoder.finish()));
            belt.recall();
            let bytes = m * HIT_BYTES + STAMP_BYTES;
            slot.readback.slice(..bytes).map_async(wgpu::MapMode::Read, |_| {});
            stats.readback_bytes += m * HIT_BYTES;
            stats.batches += 1;
            stats.rays += m;
            in_flight.push_back(InFlight { slot: k % SLOTS, rays: range, submission });
        }
        while let Some(done) = in_flight.pop_front() {
            read_back(gpu, &slots[done.slot], done, stats, out);
        }
    }

    /// Uploads `rays` once, a buffer per batch, for casting again without an upload.
    fn upload_resident(&mut self, gpu: &Gpu, key: u64, rays: &[Ray], ranges: &[Range<usize>]) -> Resident {
        let batches = ranges
            .iter()
            .map(|range| {
                pack(&rays[range.clone()], &mut self.packed);
                self.stats.upload_bytes += (range.len() as u64) * RAY_BYTES;
                wgpu::util::DeviceExt::create_buffer_init(
                    &gpu.device,
                    &wgpu::util::BufferInitDescriptor {
                        label: Some("resident rays"),
                        contents: bytemuck::cast_slice(&self.packed),
                        usage: wgpu::BufferUsages::COPY_SRC,
                    },
                )
            })
            .collect();
        self.stats.resident_uploads += 1;
        Resident { key, len: rays.len(), batches }
    }
}

/// Waits for batch `done`, appends its results to `out` and adds its device times.
fn read_back(gpu: &Gpu, slot: &Slot, done: InFlight, stats: &mut DeviceStats, out: &mut Vec<(u32, u32)>) {
    let m = done.rays.len();
    let wait = Instant::now();
    let _ = gpu.device.poll(wgpu::PollType::Wait { submission_index: Some(done.submission), timeout: None });
    stats.wait_s += wait.elapsed().as_secs_f64();
    let slice = slot.readback.slice(..m as u64 * HIT_BYTES + STAMP_BYTES);
    match slice.get_mapped_range() {
        Ok(view) => {
            let words: &[u32] = bytemuck::cast_slice(&view);
            out.extend(words[..2 * m].chunks_exact(2).map(|w| (w[0], w[1])));
            if slot.queries.is_some() {
                let t: [u64; 4] = std::array::from_fn(|i| {
                    u64::from(words[2 * m + 2 * i]) | (u64::from(words[2 * m + 2 * i + 1]) << 32)
                });
                let s = |a: u64, b: u64| b.saturating_sub(a) as f64 * gpu.timestamp_period_ns * 1e-9;
                stats.kernel_s = Some(stats.kernel_s.unwrap_or(0.0) + s(t[1], t[2]));
                if gpu.timestamps == Timestamps::Encoder {
                    stats.upload_s = Some(stats.upload_s.unwrap_or(0.0) + s(t[0], t[1]));
                    stats.readback_s = Some(stats.readback_s.unwrap_or(0.0) + s(t[2], t[3]));
                }
            }
        }
        // The readback failed (a lost device): recorded as the device's fault, which the caller
        // reports; these rays count as misses meanwhile (no silent fallback to the CPU).
        Err(e) => {
            Gpu::record_fault(
                &gpu.fault,
                format!("reading results back from the GPU `{}` failed: {e}", gpu.description),
            );
            out.extend(std::iter::repeat_n((0, MISS), m));
        }
    }
    slot.readback.unmap();
}

/// The device layout of `rays` (`cast.wgsl`): `(origin, t_max), (dir, 0)`, infinite ranges as the
/// largest finite distance (shaders may assume finite math).
fn pack(rays: &[Ray], out: &mut Vec<f32>) {
    out.clear();
    out.reserve(rays.len() * 8);
    for r in rays {
        let t_max = r.t_max.min(f32::MAX);
        out.extend_from_slice(&[r.origin.x, r.origin.y, r.origin.z, t_max, r.dir.x, r.dir.y, r.dir.z, 0.0]);
    }
}
