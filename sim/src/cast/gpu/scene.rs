//! The scene on the device: the BVH2 nodes and the triangles in leaf order as storage buffers,
//! split over up to 2 node and 4 triangle bindings when one binding cannot hold them (layouts in
//! `cast.wgsl`), and the pipeline compiled for that split.

use obvhs::bvh2::leaf_collapser::collapse;
use wgpu::util::DeviceExt;

use super::GpuError;
use super::device::Gpu;
use crate::cast::bvh::{pad_for, padded_bvh2};
use crate::scene::SceneMesh;

/// Bytes per BVH node on the device (two `vec4<f32>`) and per triangle (three).
const NODE_BYTES: u64 = 32;
const TRI_BYTES: u64 = 48;
/// Bindings the shader has for nodes and for triangles.
const NODE_BINDINGS: usize = 2;
const TRI_BINDINGS: usize = 4;
/// The shader's "no split" shift: 2^31 elements, more than any binding holds.
const NO_SPLIT: u32 = 31;

/// The scene's buffers and the pipeline that reads them.
pub(super) struct SceneBuffers {
    /// Node bindings (unused ones hold a small placeholder).
    nodes: Vec<wgpu::Buffer>,
    /// Triangle bindings (unused ones hold a small placeholder).
    tris: Vec<wgpu::Buffer>,
    /// The kernel for rays made on the host (`main` of `cast.wgsl`).
    pub(super) pipeline: wgpu::ComputePipeline,
    /// The kernel for rays made on the device from a beam set and poses (`main_beams`).
    pub(super) beam_pipeline: wgpu::ComputePipeline,
    /// Leaf order -> index into `SceneMesh::triangles`.
    pub(super) order_to_triangle: Vec<u32>,
    /// Whether the scene has no triangles (every ray misses).
    pub(super) empty: bool,
    /// How many node and triangle bindings hold data.
    pub(super) bindings_used: (usize, usize),
    /// Bytes of the nodes and of the triangles.
    pub(super) bytes: (u64, u64),
}

/// `log2` of the elements of `bytes_each` that one binding of `limit` bytes holds (a power of two,
/// so the shader splits an index with a shift and a mask).
fn shift_for(limit: u64, bytes_each: u64) -> u32 {
    let per = (limit / bytes_each).max(1);
    (63 - per.leading_zeros()).min(NO_SPLIT)
}

impl SceneBuffers {
    /// Builds the BVH2 of `mesh` (leaves of up to 4 triangles), flattens it, uploads it in
    /// bindings of at most `max_binding_bytes` and compiles the pipeline for that split.
    pub(super) fn new(gpu: &Gpu, mesh: &SceneMesh, max_binding_bytes: u64) -> Result<Self, GpuError> {
        let placeholder = || {
            gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("unused binding"),
                contents: &[0u8; 48],
                usage: wgpu::BufferUsages::STORAGE,
            })
        };
        let (mut nodes, mut tris, mut order_to_triangle) = (Vec::new(), Vec::new(), Vec::new());
        if !mesh.is_empty() {
            let mut bvh2 = padded_bvh2(mesh, pad_for(mesh), 0.02);
            collapse(&mut bvh2, 4, 3.0);
            nodes.reserve(bvh2.nodes.len() * 8);
            for n in &bvh2.nodes {
                let (lo, hi) = (n.aabb.min, n.aabb.max);
                nodes.extend_from_slice(&[lo.x, lo.y, lo.z, f32::from_bits(n.prim_count)]);
                nodes.extend_from_slice(&[hi.x, hi.y, hi.z, f32::from_bits(n.first_index)]);
            }
            order_to_triangle = bvh2.primitive_indices.clone();
            tris.reserve(order_to_triangle.len() * 12);
            // Each corner's fourth float: the triangle's mesh index (bits), for the shader's
            // tie-break between triangles at exactly the same distance.
            for &i in &order_to_triangle {
                for p in mesh.triangle(i as usize) {
                    tris.extend_from_slice(&[p.x, p.y, p.z, f32::from_bits(i)]);
                }
            }
        }
        let (node_shift, tri_shift) =
            (shift_for(max_binding_bytes, NODE_BYTES), shift_for(max_binding_bytes, TRI_BYTES));
        // The elements' floats in bindings of `2^shift` elements, each at most `bindings` of them.
        let split = |label: &'static str, data: &[f32], floats_each: usize, shift: u32, bindings: usize| {
            let per = (1usize << shift) * floats_each;
            let parts: Vec<&[f32]> = data.chunks(per).collect();
            if parts.len() > bindings {
                return Err(GpuError::TooLarge {
                    buffer: label,
                    needed_bytes: std::mem::size_of_val(data) as u64,
                    limit_bytes: bindings as u64 * max_binding_bytes,
                });
            }
            let mut buffers: Vec<wgpu::Buffer> = parts
                .iter()
                .map(|part| {
                    gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                        label: Some(label),
                        contents: bytemuck::cast_slice(part),
                        usage: wgpu::BufferUsages::STORAGE,
                    })
                })
                .collect();
            let used = buffers.len();
            buffers.resize_with(bindings, placeholder);
            Ok((buffers, used))
        };
        let bytes = (std::mem::size_of_val(nodes.as_slice()) as u64, std::mem::size_of_val(tris.as_slice()) as u64);
        let (nodes, node_bindings) = split("nodes", &nodes, 8, node_shift, NODE_BINDINGS)?;
        let (tris, tri_bindings) = split("triangles", &tris, 12, tri_shift, TRI_BINDINGS)?;
        // One binding: the shader's branches on the binding fold away.
        let constants = [
            ("NODE_SHIFT", f64::from(if node_bindings > 1 { node_shift } else { NO_SPLIT })),
            ("TRI_SHIFT", f64::from(if tri_bindings > 1 { tri_shift } else { NO_SPLIT })),
        ];
        let shader = gpu.device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("bvh2.wgsl + cast.wgsl"),
            source: wgpu::ShaderSource::Wgsl(concat!(include_str!("bvh2.wgsl"), include_str!("cast.wgsl")).into()),
        });
        let pipeline_for = |entry_point: &str| {
            gpu.device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry_point),
                layout: Some(&gpu.pipeline_layout),
                module: &shader,
                entry_point: Some(entry_point),
                compilation_options: wgpu::PipelineCompilationOptions { constants: &constants, ..Default::default() },
                cache: None,
            })
        };
        let (pipeline, beam_pipeline) = (pipeline_for("main"), pipeline_for("main_beams"));
        Ok(Self {
            nodes,
            tris,
            pipeline,
            beam_pipeline,
            empty: order_to_triangle.is_empty(),
            order_to_triangle,
            bindings_used: (node_bindings, tri_bindings),
            bytes,
        })
    }

    /// The scene's bind group entries (bindings 0 to 5 of `cast.wgsl`).
    pub(super) fn entries(&self) -> Vec<wgpu::BindGroupEntry<'_>> {
        self.nodes
            .iter()
            .chain(&self.tris)
            .enumerate()
            .map(|(i, b)| wgpu::BindGroupEntry { binding: i as u32, resource: b.as_entire_binding() })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::shift_for;

    #[test]
    fn a_binding_holds_the_largest_power_of_two_of_elements_that_fits() {
        assert_eq!(shift_for(128 << 20, 32), 22);
        assert_eq!(shift_for((128 << 20) - 1, 32), 21);
        assert_eq!(shift_for(48 * 1000, 48), 9);
        assert_eq!(shift_for(1, 48), 0);
        assert_eq!(shift_for(u64::MAX, 32), 31);
    }
}
