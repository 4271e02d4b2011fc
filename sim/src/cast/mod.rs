//! Ray casting behind one trait, [`Caster`]: the production BVH backend ([`BvhCaster`], obvhs)
//! and the reference backend ([`ParryCaster`], parry3d). Both use the same watertight
//! ray/triangle test ([`watertight`]), so a ray along a shared edge never slips through.

mod bvh;
pub mod fixture;
#[cfg(feature = "gpu")]
pub mod gpu;
mod reference;
pub mod watertight;
mod wide4;

pub use bvh::{BvhCaster, BvhLayout, BvhOptions};
pub use reference::ParryCaster;

use glam::Vec3;

use crate::scene::SceneMesh;

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
            Backend::Parry => Ok(Box::new(ParryCaster::new(mesh))),
            #[cfg(feature = "gpu")]
            Backend::Gpu => match gpu::GpuCaster::new(mesh) {
                Ok(c) => Ok(Box::new(c)),
                Err(e) => Err(crate::error::SimError::invalid("backend", "gpu", e.to_string())),
            },
            #[cfg(not(feature = "gpu"))]
            Backend::Gpu => {
                Err(crate::error::SimError::invalid("backend", "gpu", "bvh or parry: this build has no `gpu` feature"))
            }
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
}

/// Rays per parallel work item in [`Caster::cast_all`].
pub const CHUNK: usize = 256;
