//! The scene on the device: the BVH nodes (binary or compressed 8-wide, [`GpuBvh`]) and the
//! triangles in leaf order as storage buffers, split over up to 2 node and 4 triangle bindings when
//! one binding cannot hold them (layouts in `bvh2.wgsl`, `cwbvh.wgsl` and `triangles.wgsl`), and
//! the pipelines compiled for that layout and split.

use obvhs::bvh2::leaf_collapser::collapse;
use wgpu::util::DeviceExt;

use super::device::Gpu;
use super::{GpuBvh, GpuError, cwbvh};
use crate::cast::bvh::{pad_for, padded_bvh2};
use crate::scene::SceneMesh;

/// Words (`f32`, integers bitcast) per BVH2 node on the device (two `vec4<f32>`) and per
/// triangle (three).
const BVH2_NODE_WORDS: usize = 8;
const TRI_WORDS: usize = 12;
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
    /// The BVH layout of the nodes (and the traversal compiled for it).
    pub(super) bvh: GpuBvh,
}

/// `log2` of the elements of `bytes_each` that one binding of `limit` bytes holds (a power of two,
/// so the shader splits an index with a shift and a mask).
fn shift_for(limit: u64, bytes_each: u64) -> u32 {
    let per = (limit / bytes_each).max(1);
    (63 - per.leading_zeros()).min(NO_SPLIT)
}

/// The BVH2 of a non-empty `mesh` (leaves of up to 4 triangles) as `bvh2.wgsl` reads it, and its
/// leaf order (leaf-order triangle -> index into `SceneMesh::triangles`).
fn bvh2_nodes(mesh: &SceneMesh) -> (Vec<f32>, Vec<u32>) {
    let mut bvh2 = padded_bvh2(mesh, pad_for(mesh), 0.02);
    collapse(&mut bvh2, 4, 3.0);
    let mut nodes = Vec::with_capacity(bvh2.nodes.len() * BVH2_NODE_WORDS);
    for n in &bvh2.nodes {
        let (lo, hi) = (n.aabb.min, n.aabb.max);
        nodes.extend_from_slice(&[lo.x, lo.y, lo.z, f32::from_bits(n.prim_count)]);
        nodes.extend_from_slice(&[hi.x, hi.y, hi.z, f32::from_bits(n.first_index)]);
    }
    (nodes, bvh2.primitive_indices)
}

impl SceneBuffers {
    /// Builds the BVH of `mesh` in layout `bvh`, flattens it, uploads it in bindings of at most
    /// `max_binding_bytes` (for the nodes, for the triangles) and compiles the pipelines for that
    /// layout and split.
    pub(super) fn new(
        gpu: &Gpu,
        mesh: &SceneMesh,
        (node_binding_bytes, max_binding_bytes): (u64, u64),
        bvh: GpuBvh,
    ) -> Result<Self, GpuError> {
        let placeholder = || {
            gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("unused binding"),
                contents: &[0u8; 80],
                usage: wgpu::BufferUsages::STORAGE,
            })
        };
        let node_words = match bvh {
            GpuBvh::Bvh2 => BVH2_NODE_WORDS,
            GpuBvh::Cwbvh => cwbvh::NODE_WORDS,
        };
        let (mut nodes, mut tris, mut order_to_triangle) = (Vec::new(), Vec::new(), Vec::new());
        if !mesh.is_empty() {
            (nodes, order_to_triangle) = match bvh {
                GpuBvh::Bvh2 => bvh2_nodes(mesh),
                GpuBvh::Cwbvh => cwbvh::build(mesh),
            };
            tris.reserve(order_to_triangle.len() * TRI_WORDS);
            // Each corner's fourth float: the triangle's mesh index (bits), for the shader's
            // tie-break between triangles at exactly the same distance.
            for &i in &order_to_triangle {
                for p in mesh.triangle(i as usize) {
                    tris.extend_from_slice(&[p.x, p.y, p.z, f32::from_bits(i)]);
                }
            }
        }
        let (node_shift, tri_shift) =
            (shift_for(node_binding_bytes, 4 * node_words as u64), shift_for(max_binding_bytes, 4 * TRI_WORDS as u64));
        // The elements' floats in bindings of `2^shift` elements, each at most `bindings` of them.
        let split = |label: &'static str, data: &[f32], floats_each: usize, shift: u32, limit: u64, bindings: usize| {
            let per = (1usize << shift) * floats_each;
            let parts: Vec<&[f32]> = data.chunks(per).collect();
            if parts.len() > bindings {
                return Err(GpuError::TooLarge {
                    buffer: label,
                    needed_bytes: std::mem::size_of_val(data) as u64,
                    limit_bytes: bindings as u64 * limit,
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
        let (nodes, node_bindings) = split("nodes", &nodes, node_words, node_shift, node_binding_bytes, NODE_BINDINGS)?;
        let (tris, tri_bindings) = split("triangles", &tris, TRI_WORDS, tri_shift, max_binding_bytes, TRI_BINDINGS)?;
        // One binding: the shader's branches on the binding fold away.
        let constants = [
            ("NODE_SHIFT", f64::from(if node_bindings > 1 { node_shift } else { NO_SPLIT })),
            ("TRI_SHIFT", f64::from(if tri_bindings > 1 { tri_shift } else { NO_SPLIT })),
            ("NODE_VEC4S", (node_words / 4) as f64),
        ];
        // One module: the triangles, the nodes, the traversal of the layout, the kernels.
        let (label, source) = match bvh {
            GpuBvh::Bvh2 => (
                "triangles.wgsl + nodes.wgsl + bvh2.wgsl + cast.wgsl",
                concat!(
                    include_str!("triangles.wgsl"),
                    include_str!("nodes.wgsl"),
                    include_str!("bvh2.wgsl"),
                    include_str!("cast.wgsl")
                ),
            ),
            GpuBvh::Cwbvh => (
                "triangles.wgsl + nodes.wgsl + cwbvh.wgsl + cast.wgsl",
                concat!(
                    include_str!("triangles.wgsl"),
                    include_str!("nodes.wgsl"),
                    include_str!("cwbvh.wgsl"),
                    include_str!("cast.wgsl")
                ),
            ),
        };
        let shader = gpu.device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(label),
            source: wgpu::ShaderSource::Wgsl(source.into()),
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
            bvh,
        })
    }

    /// The scene's bind group entries (bindings 0 to 5: the nodes, then the triangles).
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
