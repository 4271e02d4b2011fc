//! The scene on the device: the BVH2 nodes and the triangles in leaf order as storage buffers, and
//! the batched casting of rays through them (layouts in `cast.wgsl`).

use obvhs::bvh2::leaf_collapser::collapse;
use wgpu::util::DeviceExt;

use super::GpuError;
use super::device::Gpu;
use crate::cast::Ray;
use crate::cast::bvh::{pad_for, padded_bvh2};
use crate::scene::SceneMesh;

/// Result triangle of a ray that hit nothing.
pub(super) const MISS: u32 = u32::MAX;
/// Result triangle of a ray whose traversal overflowed the shader's stack.
pub(super) const OVERFLOW: u32 = u32::MAX - 1;

/// Rays per dispatch at most (a workgroup of 64 per 64 rays, under the 65,535-workgroup limit).
const MAX_BATCH_RAYS: u64 = 1 << 20;

/// Bytes per ray on the device (two `vec4<f32>`) and per result (`vec2<u32>`).
const RAY_BYTES: u64 = 32;
const HIT_BYTES: u64 = 8;

/// The scene's buffers.
pub(super) struct SceneBuffers {
    nodes: wgpu::Buffer,
    tris: wgpu::Buffer,
    /// Leaf order -> index into `SceneMesh::triangles`.
    pub(super) order_to_triangle: Vec<u32>,
    /// Whether the scene has no triangles (every ray misses).
    empty: bool,
}

impl SceneBuffers {
    /// Builds the BVH2 of `mesh` (leaves of up to 4 triangles), flattens it and uploads it.
    pub(super) fn new(gpu: &Gpu, mesh: &SceneMesh) -> Result<Self, GpuError> {
        let dummy = |gpu: &Gpu, label| {
            gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: &[0u8; 32],
                usage: wgpu::BufferUsages::STORAGE,
            })
        };
        if mesh.is_empty() {
            return Ok(Self {
                nodes: dummy(gpu, "nodes"),
                tris: dummy(gpu, "triangles"),
                order_to_triangle: Vec::new(),
                empty: true,
            });
        }
        let mut bvh2 = padded_bvh2(mesh, pad_for(mesh), 0.02);
        collapse(&mut bvh2, 4, 3.0);
        let mut nodes: Vec<f32> = Vec::with_capacity(bvh2.nodes.len() * 8);
        for n in &bvh2.nodes {
            let (lo, hi) = (n.aabb.min, n.aabb.max);
            nodes.extend_from_slice(&[lo.x, lo.y, lo.z, f32::from_bits(n.prim_count)]);
            nodes.extend_from_slice(&[hi.x, hi.y, hi.z, f32::from_bits(n.first_index)]);
        }
        let order_to_triangle = bvh2.primitive_indices.clone();
        let mut tris: Vec<f32> = Vec::with_capacity(order_to_triangle.len() * 12);
        for &i in &order_to_triangle {
            for p in mesh.triangle(i as usize) {
                tris.extend_from_slice(&[p.x, p.y, p.z, 0.0]);
            }
        }
        let upload = |label: &'static str, data: &[f32]| -> Result<wgpu::Buffer, GpuError> {
            let bytes = std::mem::size_of_val(data) as u64;
            if bytes > gpu.max_binding_bytes {
                return Err(GpuError::TooLarge {
                    buffer: label,
                    needed_bytes: bytes,
                    limit_bytes: gpu.max_binding_bytes,
                });
            }
            Ok(gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: bytemuck::cast_slice(data),
                usage: wgpu::BufferUsages::STORAGE,
            }))
        };
        Ok(Self { nodes: upload("nodes", &nodes)?, tris: upload("triangles", &tris)?, order_to_triangle, empty: false })
    }

    /// `(t bits, leaf-order triangle or MISS / OVERFLOW)` per ray, in batches the device binds.
    pub(super) fn cast(&self, gpu: &Gpu, rays: &[Ray]) -> Vec<(u32, u32)> {
        if self.empty || rays.is_empty() {
            return vec![(0, MISS); rays.len()];
        }
        let batch = (gpu.max_binding_bytes / RAY_BYTES).clamp(64, MAX_BATCH_RAYS) as usize;
        let n = rays.len().min(batch);
        let usage_in = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST;
        let ray_buf = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("rays"),
            size: n as u64 * RAY_BYTES,
            usage: usage_in,
            mapped_at_creation: false,
        });
        let hit_buf = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("hits"),
            size: n as u64 * HIT_BYTES,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let read_buf = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size: n as u64 * HIT_BYTES,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let params = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("params"),
            size: 16,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let bind = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("caster"),
            layout: &gpu.layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: self.nodes.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: self.tris.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 2, resource: ray_buf.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 3, resource: hit_buf.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 4, resource: params.as_entire_binding() },
            ],
        });
        let mut out = Vec::with_capacity(rays.len());
        let mut packed: Vec<f32> = Vec::with_capacity(n * 8);
        for chunk in rays.chunks(n) {
            packed.clear();
            for r in chunk {
                // Infinite ranges as the largest finite distance (shaders may assume finite math).
                let t_max = r.t_max.min(f32::MAX);
                packed.extend_from_slice(&[r.origin.x, r.origin.y, r.origin.z, t_max, r.dir.x, r.dir.y, r.dir.z, 0.0]);
            }
            let m = chunk.len() as u64;
            gpu.queue.write_buffer(&ray_buf, 0, bytemuck::cast_slice(&packed));
            gpu.queue.write_buffer(&params, 0, bytemuck::cast_slice(&[chunk.len() as u32, 0, 0, 0]));
            let mut encoder =
                gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("cast") });
            {
                let mut pass = encoder
                    .begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("cast"), timestamp_writes: None });
                pass.set_pipeline(&gpu.pipeline);
                pass.set_bind_group(0, &bind, &[]);
                pass.dispatch_workgroups((chunk.len() as u32).div_ceil(64), 1, 1);
            }
            encoder.copy_buffer_to_buffer(&hit_buf, 0, &read_buf, 0, m * HIT_BYTES);
            gpu.queue.submit(Some(encoder.finish()));
            let slice = read_buf.slice(..m * HIT_BYTES);
            slice.map_async(wgpu::MapMode::Read, |_| {});
            let _ = gpu.device.poll(wgpu::PollType::wait_indefinitely());
            match slice.get_mapped_range() {
                Ok(view) => {
                    let words: &[u32] = bytemuck::cast_slice(&view);
                    out.extend(words.chunks_exact(2).map(|w| (w[0], w[1])));
                }
                // The readback failed (a lost device): these rays go to the CPU caster.
                Err(_) => out.extend(std::iter::repeat_n((0, OVERFLOW), chunk.len())),
            }
            read_buf.unmap();
        }
        out
    }
}
