//! The GPU backend (cargo feature `gpu`): an obvhs BVH built on the CPU, flattened into storage
//! buffers and traversed by a WGSL compute shader (`cast.wgsl`, one ray per invocation) with the
//! watertight triangle test of [`super::watertight`] in f32. The BVH ([`GpuBvh`], or
//! `GROUNDTRUTH_GPU_BVH`): by default the compressed 8-wide BVH (CWBVH) obvhs converts from its
//! BVH2 (`cwbvh.wgsl`, a stack of node groups, children in the ray octant's order; measured on
//! lavapipe 2.2 to 2.4 times the BVH2's kernel speed), or that BVH2 itself (`bvh2.wgsl`, a
//! 64-entry stack, nearer child first).
//! It runs on any Vulkan, Metal or DX12 device through wgpu, including Mesa's software Vulkan
//! (lavapipe) without a GPU.
//!
//! - The adapter follows wgpu's environment conventions: `WGPU_BACKEND` picks the backends and
//!   `WGPU_ADAPTER_NAME` an adapter by name (a substring, case-insensitive); otherwise wgpu's
//!   default (high-performance preference from `WGPU_POWER_PREF`). The fallback adapter is never
//!   forced, so a real GPU is used where there is one.
//! - Hits carry the distance and the triangle, as the CPU backends' do, so labels, normals and
//!   measurement effects stay shared code.
//! - A scene larger than one storage binding is split over up to 2 node and 4 triangle bindings
//!   ([`scene`]); rays go through in batches within the binding and dispatch limits, two batch
//!   slots kept across calls, the next batch uploaded and run while the previous one is read back
//!   ([`stream`]). The scanner hands over a whole frame per call ([`Caster::prefers_frames`]), and a
//!   standing rig's rays once ([`Caster::cast_all_resident`]): they stay on the device.
//! - Where the adapter has timestamp queries, [`GpuCaster::stats`] splits the device's time into
//!   the upload copy, the kernel and the readback copy.
//! - Limits: no f64 fallback in the triangle test (a ray exactly through a shared edge may report
//!   the other triangle, as ties may on the CPU); rays whose traversal overflows the stack are cast
//!   again on the CPU (counted); a moving rig's rays are made on the CPU and uploaded every frame,
//!   because rays transformed on the device (its `sqrt` and division are not correctly rounded)
//!   would not be the same bits as the CPU backends' and scans would no longer match them.

mod cwbvh;
mod device;
mod scene;
mod stream;

use std::sync::Mutex;

use thiserror::Error;

use super::{BeamSet, BvhCaster, Caster, DeviceStats, Hit, Ray};
use crate::scene::SceneMesh;

pub use device::adapter_description;

/// Why the GPU backend could not start.
#[derive(Debug, Error)]
pub enum GpuError {
    /// No adapter matched (no Vulkan / Metal / DX12 driver, or `WGPU_ADAPTER_NAME` matched none).
    #[error(
        "no GPU adapter: {0} (install a Vulkan driver, e.g. Mesa's `mesa-vulkan-drivers`, or unset WGPU_BACKEND / WGPU_ADAPTER_NAME)"
    )]
    NoAdapter(String),
    /// The adapter refused a device with the limits the caster needs.
    #[error("the GPU adapter `{adapter}` gave no device: {reason}")]
    Device {
        /// The adapter's name.
        adapter: String,
        /// wgpu's message.
        reason: String,
    },
    /// The scene does not fit the device's buffers.
    #[error("the scene needs a {needed_bytes}-byte {buffer} buffer; the device binds at most {limit_bytes} bytes")]
    TooLarge {
        /// Which buffer.
        buffer: &'static str,
        /// Its size, bytes.
        needed_bytes: u64,
        /// The device's storage-binding limit, bytes.
        limit_bytes: u64,
    },
    /// An environment variable of the backend has a value it does not know.
    #[error("{variable} is `{value}`; allowed: {allowed}")]
    Env {
        /// The variable.
        variable: &'static str,
        /// Its value.
        value: String,
        /// The values it may take.
        allowed: &'static str,
    },
}

/// The BVH layout the GPU traverses (both are built from the same obvhs BVH2; the hits are the
/// same but for ties and the rounding of the box tests).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum GpuBvh {
    /// The binary BVH, leaves of up to 4 triangles, nearer child first (`bvh2.wgsl`).
    Bvh2,
    /// The compressed 8-wide BVH (CWBVH, Ylitie et al. 2017: 80-byte nodes, child boxes quantized
    /// to 8 bits, leaves of up to 3 triangles, children in the ray octant's order; `cwbvh.wgsl`).
    /// The default: the faster (on lavapipe, `bench raycast`: 2.2 times the BVH2's kernel speed on
    /// `city` with `hdl64e-roof`, 2.4 times on the 1.3 M-triangle fixture terrain).
    #[default]
    Cwbvh,
}

impl GpuBvh {
    /// The environment variable [`GpuCaster::new`] takes the layout from: `bvh2` or `cwbvh`.
    pub const ENV: &'static str = "GROUNDTRUTH_GPU_BVH";

    /// The layout [`GpuBvh::ENV`] names, `None` where it is unset or empty; [`GpuError::Env`] for
    /// another value.
    pub fn from_env() -> Result<Option<Self>, GpuError> {
        match std::env::var(Self::ENV) {
            Ok(v) if !v.trim().is_empty() => v.parse().map(Some),
            _ => Ok(None),
        }
    }

    /// The layout's name, as [`GpuBvh::ENV`] takes it.
    pub fn name(self) -> &'static str {
        match self {
            Self::Bvh2 => "bvh2",
            Self::Cwbvh => "cwbvh",
        }
    }
}

impl std::fmt::Display for GpuBvh {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for GpuBvh {
    type Err = GpuError;

    /// `bvh2` or `cwbvh` (case-insensitive, surrounding blanks ignored).
    fn from_str(s: &str) -> Result<Self, GpuError> {
        match s.trim().to_ascii_lowercase().as_str() {
            "bvh2" => Ok(Self::Bvh2),
            "cwbvh" => Ok(Self::Cwbvh),
            _ => Err(GpuError::Env { variable: Self::ENV, value: s.to_owned(), allowed: "bvh2, cwbvh" }),
        }
    }
}

/// Options of [`GpuCaster::with_options`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GpuOptions {
    /// Largest storage binding to use, bytes (`None`: the device's limit). A smaller value splits
    /// the scene over more bindings and the rays into smaller batches, as a device with that
    /// limit would (tests use it to exercise the splits on a small scene).
    pub max_binding_bytes: Option<u64>,
    /// The BVH layout to traverse.
    pub bvh: GpuBvh,
    /// Largest binding for the BVH nodes alone, bytes (`None`: as the others). Tests only: the
    /// CWBVH's nodes take a fifth of its triangles' bytes, so no binding limit that lets the
    /// triangles fit their 4 bindings splits its nodes; this does.
    #[doc(hidden)]
    pub max_node_binding_bytes: Option<u64>,
}

/// Ray casting on a GPU through wgpu (module docs).
pub struct GpuCaster {
    gpu: device::Gpu,
    scene: scene::SceneBuffers,
    /// CPU caster for the rays whose traversal overflows the stack.
    cpu: BvhCaster,
    /// Batch slots, upload belt, resident rays and counters; one caller at a time.
    stream: Mutex<stream::Stream>,
    max_binding_bytes: u64,
}

impl GpuCaster {
    /// Builds the BVH of `mesh`, uploads it and compiles the shader on the adapter wgpu's
    /// environment variables choose (module docs), in the layout [`GpuBvh::ENV`] names (default
    /// [`GpuBvh::default`]; [`GpuError::Env`] for a value it does not know).
    pub fn new(mesh: &SceneMesh) -> Result<Self, GpuError> {
        let bvh = GpuBvh::from_env()?.unwrap_or_default();
        Self::with_options(mesh, GpuOptions { bvh, ..GpuOptions::default() })
    }

    /// [`GpuCaster::new`] with `options` (the layout as they say, whatever the environment).
    pub fn with_options(mesh: &SceneMesh, options: GpuOptions) -> Result<Self, GpuError> {
        let mut gpu = device::Gpu::new()?;
        let max_binding_bytes =
            options.max_binding_bytes.map_or(gpu.max_binding_bytes, |b| b.clamp(256, gpu.max_binding_bytes));
        gpu.max_binding_bytes = max_binding_bytes;
        let node_binding_bytes =
            options.max_node_binding_bytes.map_or(max_binding_bytes, |b| b.clamp(256, max_binding_bytes));
        let scene = scene::SceneBuffers::new(&gpu, mesh, (node_binding_bytes, max_binding_bytes), options.bvh)?;
        let stream = Mutex::new(stream::Stream::new(&gpu));
        Ok(Self { gpu, scene, cpu: BvhCaster::new(mesh), stream, max_binding_bytes })
    }

    /// The adapter in use: name, backend and device type.
    pub fn adapter(&self) -> &str {
        &self.gpu.description
    }

    /// The BVH layout in use.
    pub fn bvh(&self) -> GpuBvh {
        self.scene.bvh
    }

    /// The largest storage binding in use, bytes.
    pub fn max_binding_bytes(&self) -> u64 {
        self.max_binding_bytes
    }

    /// How many node and triangle bindings the scene occupies (more than one when it exceeds
    /// [`GpuCaster::max_binding_bytes`]).
    pub fn bindings_used(&self) -> (usize, usize) {
        self.scene.bindings_used
    }

    /// Bytes of the scene's BVH nodes and of its triangles on the device.
    pub fn scene_bytes(&self) -> (u64, u64) {
        self.scene.bytes
    }

    /// How many rays so far were cast again on the CPU because their traversal overflowed the
    /// shader's stack.
    pub fn cpu_fallbacks(&self) -> u64 {
        self.stats().cpu_fallbacks
    }

    /// Destroys the device, as an adapter that disappears mid-run would (tests of the error path):
    /// later calls record [`Caster::fault`] and return misses.
    #[doc(hidden)]
    pub fn destroy_device(&self) {
        self.gpu.device.destroy();
    }

    /// Counters and times of everything cast so far.
    pub fn stats(&self) -> DeviceStats {
        self.lock().stats
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, stream::Stream> {
        // A panic while the lock was held leaves the counters, at worst, short of one batch.
        self.stream.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    /// Casts `rays` on the GPU (kept on the device under `resident`); `out[i]` receives the
    /// closest hit of `rays[i]`.
    fn cast_gpu(&self, rays: &[Ray], resident: Option<u64>, out: &mut [Option<Hit>]) {
        let mut raw = Vec::with_capacity(rays.len());
        let mut stream = self.lock();
        stream.cast(&self.gpu, &self.scene, rays, resident, &mut raw);
        for ((o, ray), (t_bits, prim)) in out.iter_mut().zip(rays).zip(raw) {
            *o = match prim {
                stream::MISS => None,
                stream::OVERFLOW => {
                    stream.stats.cpu_fallbacks += 1;
                    self.cpu.cast(ray)
                }
                p => Some(Hit { t: f32::from_bits(t_bits), triangle: self.scene.order_to_triangle[p as usize] }),
            };
        }
    }
}

impl Caster for GpuCaster {
    fn cast(&self, ray: &Ray) -> Option<Hit> {
        let mut out = [None];
        self.cast_gpu(std::slice::from_ref(ray), None, &mut out);
        out[0]
    }

    fn cast_batch(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        self.cast_gpu(rays, None, out);
    }

    /// All rays in one stream of batches (no rayon: the device runs them in parallel).
    fn cast_all(&self, rays: &[Ray]) -> Vec<Option<Hit>> {
        let mut out = vec![None; rays.len()];
        self.cast_gpu(rays, None, &mut out);
        out
    }

    fn cast_all_resident(&self, key: u64, rays: &[Ray]) -> Vec<Option<Hit>> {
        let mut out = vec![None; rays.len()];
        self.cast_gpu(rays, Some(key), &mut out);
        out
    }

    /// The beams kept on the device, the rays made there (module docs); a set that does not fit a
    /// binding with one frame's poses is cast from rays made on the host.
    fn cast_beams(&self, beams: &BeamSet, poses: &[glam::Affine3A]) -> Vec<Option<Hit>> {
        let mut raw = Vec::new();
        let mut stream = self.lock();
        if stream.cast_beams(&self.gpu, &self.scene, beams, poses, &mut raw).is_err() {
            drop(stream);
            // Made on this thread: callers may be casting threads that must not wait on a pool.
            let rays: Vec<Ray> =
                (0..beams.beams().len() * beams.frames_in(poses)).map(|r| beams.call_ray(r, poses)).collect();
            return self.cast_all(&rays);
        }
        raw.into_iter()
            .enumerate()
            .map(|(r, (t_bits, prim))| match prim {
                stream::MISS => None,
                stream::OVERFLOW => {
                    stream.stats.cpu_fallbacks += 1;
                    self.cpu.cast(&beams.call_ray(r, poses))
                }
                p => Some(Hit { t: f32::from_bits(t_bits), triangle: self.scene.order_to_triangle[p as usize] }),
            })
            .collect()
    }

    fn prefers_frames(&self) -> bool {
        true
    }

    fn device_stats(&self) -> Option<DeviceStats> {
        Some(self.stats())
    }

    fn fault(&self) -> Option<String> {
        self.gpu.fault()
    }
}
