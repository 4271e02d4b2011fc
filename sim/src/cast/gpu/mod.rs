//! The GPU backend (cargo feature `gpu`): the obvhs BVH2 built on the CPU, flattened into storage
//! buffers and traversed by a WGSL compute shader (`cast.wgsl`, one ray per invocation, a 64-entry
//! stack, nearer child first) with the watertight triangle test of [`super::watertight`] in f32.
//! It runs on any Vulkan, Metal or DX12 device through wgpu, including Mesa's software Vulkan
//! (lavapipe) without a GPU.
//!
//! - The adapter follows wgpu's environment conventions: `WGPU_BACKEND` picks the backends and
//!   `WGPU_ADAPTER_NAME` an adapter by name (a substring, case-insensitive); otherwise wgpu's
//!   default (high-performance preference from `WGPU_POWER_PREF`). The fallback adapter is never
//!   forced, so a real GPU is used where there is one.
//! - Hits carry the distance and the triangle, as the CPU backends' do, so labels, normals and
//!   measurement effects stay shared code.
//! - Rays go to the device in batches that respect the device's storage-binding size limit; the
//!   batch buffers are reused across the batches of a call.
//! - Limits of this first version: no f64 fallback in the triangle test (a ray exactly through a
//!   shared edge may report the other triangle, as ties may on the CPU), rays whose traversal
//!   overflows the stack are cast again on the CPU (counted by [`GpuCaster::cpu_fallbacks`]),
//!   readback is synchronous and the rays are uploaded for every call rather than generated on
//!   the GPU.

mod device;
mod layout;

use std::sync::atomic::{AtomicU64, Ordering};

use thiserror::Error;

use super::{BvhCaster, Caster, Hit, Ray};
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
}

/// Ray casting on a GPU through wgpu (module docs).
pub struct GpuCaster {
    gpu: device::Gpu,
    scene: layout::SceneBuffers,
    /// CPU caster for the rays whose traversal overflows the stack, and for single rays.
    cpu: BvhCaster,
    fallbacks: AtomicU64,
}

impl GpuCaster {
    /// Builds the BVH of `mesh`, uploads it and compiles the shader on the adapter wgpu's
    /// environment variables choose (module docs).
    pub fn new(mesh: &SceneMesh) -> Result<Self, GpuError> {
        let gpu = device::Gpu::new()?;
        let scene = layout::SceneBuffers::new(&gpu, mesh)?;
        Ok(Self { gpu, scene, cpu: BvhCaster::new(mesh), fallbacks: AtomicU64::new(0) })
    }

    /// The adapter in use: name, backend and device type.
    pub fn adapter(&self) -> &str {
        &self.gpu.description
    }

    /// How many rays so far were cast again on the CPU because their traversal overflowed the
    /// shader's stack.
    pub fn cpu_fallbacks(&self) -> u64 {
        self.fallbacks.load(Ordering::Relaxed)
    }

    /// Casts `rays` on the GPU; `out[i]` receives the closest hit of `rays[i]`.
    fn cast_gpu(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        let raw = self.scene.cast(&self.gpu, rays);
        for ((o, ray), (t_bits, prim)) in out.iter_mut().zip(rays).zip(raw) {
            *o = match prim {
                layout::MISS => None,
                layout::OVERFLOW => {
                    self.fallbacks.fetch_add(1, Ordering::Relaxed);
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
        self.cast_gpu(std::slice::from_ref(ray), &mut out);
        out[0]
    }

    fn cast_batch(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        self.cast_gpu(rays, out);
    }

    /// All rays in one submission per batch (no rayon: the device runs them in parallel).
    fn cast_all(&self, rays: &[Ray]) -> Vec<Option<Hit>> {
        let mut out = vec![None; rays.len()];
        self.cast_gpu(rays, &mut out);
        out
    }
}
