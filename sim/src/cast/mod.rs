//! Ray casting behind one trait, [`Caster`]: the production BVH backend ([`BvhCaster`], obvhs)
//! and the reference backend ([`ParryCaster`], parry3d). Both use the same watertight
//! ray/triangle test ([`watertight`]), so a ray along a shared edge never slips through.

mod beams;
mod bvh;
pub mod fixture;
#[cfg(feature = "gpu")]
pub mod gpu;
#[cfg(feature = "reference")]
mod reference;
mod tri_pack;
pub mod watertight;
mod wide;

pub use beams::{Beam, BeamSet, BeamSetError};
pub use bvh::{BvhCaster, BvhLayout, BvhOptions};
#[cfg(feature = "reference")]
pub use reference::ParryCaster;

use glam::Vec3;

use crate::scene::SceneMesh;

/// The GPU adapter `--backend gpu` would cast on, described (name, API, kind); why not where there
/// is none, or where this build has no cargo feature `gpu`.
pub fn gpu_adapter() -> Result<String, String> {
    #[cfg(feature = "gpu")]
    return gpu::adapter_description().map_err(|e| e.to_string());
    #[cfg(not(feature = "gpu"))]
    Err(GPU_NOT_BUILT.to_string())
}

/// Why a build without the cargo feature `gpu` has no GPU backend, and how to get one.
pub const GPU_NOT_BUILT: &str =
    "not in this build (cargo feature `gpu`: `cargo install --path . --features full`, or `--features gpu`)";

/// Whether this build has the reference caster ([`Backend::Parry`]; cargo feature `reference`).
pub const REFERENCE_BUILT: bool = cfg!(feature = "reference");

/// Why a build without the cargo feature `reference` has no reference caster, and how to get one.
pub const REFERENCE_NOT_BUILT: &str = "not in this build (cargo feature `reference`: `cargo install --path . --features full`, or `--features reference`)";

/// A ray: `origin + t * dir` for `t` in `[0, t_max]`; `dir` is unit length so `t` is metres.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Origin, metres, world frame.
    pub origin: Vec3,
    /// Unit direction.
    pub dir: Vec3,
    /// Largest distance considered, metres.
    pub t_max: f32,
}

/// The closest intersection of a ray with the scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Distance along the ray, metres.
    pub t: f32,
    /// Index of the triangle hit, into [`SceneMesh::triangles`].
    pub triangle: u32,
}

/// Which caster implementation to use.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Backend {
    /// obvhs BVH with watertight triangles: the production backend.
    #[default]
    Bvh,
    /// parry3d TriMesh queries with the same watertight test: the reference backend.
    Parry,
    /// wgpu compute shaders on the GPU wgpu's environment variables choose (feature `gpu`;
    /// [`gpu::GpuCaster`]).
    Gpu,
}

impl Backend {
    /// Name used in benchmarks and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Backend::Bvh => "obvhs-bvh",
            Backend::Parry => "parry3d",
            Backend::Gpu => "wgpu",
        }
    }

    /// Builds this backend's acceleration structure over `mesh`; the GPU backend fails without an
    /// adapter, or in a build without the `gpu` feature.
    pub fn build(self, mesh: &SceneMesh) -> crate::error::Result<Box<dyn Caster>> {
        match self {
            Backend::Bvh => Ok(Box::new(BvhCaster::new(mesh))),
            #[cfg(feature = "reference")]
            Backend::Parry => Ok(Box::new(ParryCaster::new(mesh))),
            #[cfg(not(feature = "reference"))]
            Backend::Parry => Err(crate::error::SimError::invalid(
                "backend",
                "parry",
                format!("bvh: the reference backend is {REFERENCE_NOT_BUILT}"),
            )),
            #[cfg(feature = "gpu")]
            Backend::Gpu => match gpu::GpuCaster::new(mesh) {
                Ok(c) => Ok(Box::new(c)),
                // A bad layout variable is named as the field at fault.
                Err(gpu::GpuError::Env { variable, value, allowed }) => {
                    Err(crate::error::SimError::invalid(variable, value, allowed))
                }
                Err(e) => Err(crate::error::SimError::invalid("backend", "gpu", e.to_string())),
            },
            #[cfg(not(feature = "gpu"))]
            Backend::Gpu => Err(crate::error::SimError::invalid(
                "backend",
                "gpu",
                format!("bvh or parry: the GPU backend is {GPU_NOT_BUILT}"),
            )),
        }
    }
}

/// Closest-hit ray casting against one scene.
pub trait Caster: Send + Sync {
    /// Closest hit of one ray, or `None`.
    fn cast(&self, ray: &Ray) -> Option<Hit>;

    /// Casts a batch of rays on the calling thread; `out[i]` receives the result of `rays[i]`.
    /// Backends override this to exploit coherence (LiDAR rays arrive sorted by azimuth and elevation).
    fn cast_batch(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        for (r, o) in rays.iter().zip(out.iter_mut()) {
            *o = self.cast(r);
        }
    }

    /// Casts all rays in parallel (rayon), in fixed-size chunks so results never depend on the
    /// thread count.
    fn cast_all(&self, rays: &[Ray]) -> Vec<Option<Hit>> {
        use rayon::prelude::*;
        let mut out = vec![None; rays.len()];
        out.par_chunks_mut(CHUNK).zip(rays.par_chunks(CHUNK)).for_each(|(o, r)| self.cast_batch(r, o));
        out
    }

    /// [`Caster::cast_all`] for a ray set the caller casts again unchanged under the same `key`
    /// (a standing rig's rays, every frame): a device backend keeps it on the device and uploads it
    /// once. Keys come from [`new_ray_set_key`]; the caller must not reuse a key for other rays.
    fn cast_all_resident(&self, key: u64, rays: &[Ray]) -> Vec<Option<Hit>> {
        let _ = key;
        self.cast_all(rays)
    }

    /// Casts `beams` from each frame's poses (`poses`: [`BeamSet::poses_per_frame`] per frame,
    /// frame after frame): the hits of every frame in turn, each in beam order. A device backend
    /// keeps the beams on the device and makes the rays there (its rays may differ from the host's
    /// in the last bits: [`crate::scan::AgreementContract`]); the default makes them on the host
    /// ([`BeamSet::rays`]) and casts them with [`Caster::cast_all`]. A backend that
    /// [`Caster::prefers_frames`] is called from the scanner's casting thread while rayon workers
    /// may all be blocked waiting for it (`Scanner::scan_frames`): its `cast_beams` must not wait
    /// on the rayon pool.
    fn cast_beams(&self, beams: &BeamSet, poses: &[glam::Affine3A]) -> Vec<Option<Hit>> {
        self.cast_all(&beams.rays(poses))
    }

    /// Whether the backend wants a whole frame's rays per call ([`Caster::cast_all`]) rather than
    /// a row per call from many threads ([`Caster::cast_batch`]): true for the GPU, where each call
    /// is a round trip to the device.
    fn prefers_frames(&self) -> bool {
        false
    }

    /// What went wrong on a device backend's device (out of memory, a lost device), if anything:
    /// results since may be wrong, and callers stop with this message. `None` for host backends.
    fn fault(&self) -> Option<String> {
        None
    }

    /// Device counters and times for backends that run on a device, else `None`.
    fn device_stats(&self) -> Option<DeviceStats> {
        None
    }
}

/// A key for [`Caster::cast_all_resident`], unique in this process.
pub fn new_ray_set_key() -> u64 {
    use std::sync::atomic::{AtomicU64, Ordering};
    static NEXT: AtomicU64 = AtomicU64::new(1);
    NEXT.fetch_add(1, Ordering::Relaxed)
}

/// What a device backend did so far: batches, rays and bytes moved, and where the time went.
/// Device times come from timestamp queries and are `None` where the adapter has none (or, for the
/// copies, takes timestamps only around compute passes).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DeviceStats {
    /// Batches dispatched.
    pub batches: u64,
    /// Rays cast on the device.
    pub rays: u64,
    /// Rays cast again on the CPU (stack overflow or a failed readback).
    pub cpu_fallbacks: u64,
    /// Bytes of rays uploaded (resident ray sets once).
    pub upload_bytes: u64,
    /// Bytes of results read back.
    pub readback_bytes: u64,
    /// Ray sets made resident on the device.
    pub resident_uploads: u64,
    /// Host time inside the device backend's casting calls, seconds.
    pub wall_s: f64,
    /// Host time blocked waiting for the device, seconds.
    pub wait_s: f64,
    /// Device time in the casting kernel, seconds.
    pub kernel_s: Option<f64>,
    /// Device time copying rays into the kernel's buffer, seconds.
    pub upload_s: Option<f64>,
    /// Device time copying results to the host-visible buffer, seconds.
    pub readback_s: Option<f64>,
}

/// Rays per parallel work item in [`Caster::cast_all`].
pub const CHUNK: usize = 256;
