//! The compressed 8-wide BVH (CWBVH, Ylitie et al. 2017) of `cwbvh.wgsl`: obvhs converts the same
//! padded BVH2 the binary layout starts from (its leaves of one triangle each, which the converter
//! needs; it groups them into leaves of up to 3 by its SAH cost) and orders each node's children
//! by octant; the nodes are flattened here into the shader's 5 `vec4` (80 bytes) per node.

use obvhs::cwbvh::bvh2_to_cwbvh::bvh2_to_cwbvh;
use obvhs::cwbvh::node::CwBvhNode;

use crate::cast::bvh::{pad_for, padded_bvh2};
use crate::scene::SceneMesh;

/// Words (as `f32`, integers bitcast) per node on the device: 5 `vec4`.
pub(super) const NODE_WORDS: usize = 20;
/// Largest number of triangles per leaf (the CWBVH's meta byte encodes 1 to 3).
const MAX_LEAF: u32 = 3;

/// The CWBVH of a non-empty `mesh`: its nodes in the layout of `cwbvh.wgsl`, and the leaf order
/// (leaf-order triangle -> index into `SceneMesh::triangles`).
pub(super) fn build(mesh: &SceneMesh) -> (Vec<f32>, Vec<u32>) {
    let bvh2 = padded_bvh2(mesh, pad_for(mesh), 0.02);
    let cw = bvh2_to_cwbvh(&bvh2, MAX_LEAF, true, false);
    let mut words = Vec::with_capacity(cw.nodes.len() * NODE_WORDS);
    for n in &cw.nodes {
        push_node(n, &mut words);
    }
    (words, cw.primitive_indices)
}

/// Appends node `n` as `cwbvh.wgsl` reads it (the field order of obvhs's `repr(C)` node, written
/// out field by field so that the layout does not rest on the struct's).
fn push_node(n: &CwBvhNode, out: &mut Vec<f32>) {
    let bits = f32::from_bits;
    // Four bytes as one little-endian word (the shader takes byte k as bits 8k..8k + 7).
    let word = |b: &[u8]| bits(u32::from_le_bytes([b[0], b[1], b[2], b[3]]));
    let [e0, e1, e2] = n.e;
    out.extend_from_slice(&[n.p.x, n.p.y, n.p.z, word(&[e0, e1, e2, n.imask])]);
    out.extend_from_slice(&[
        bits(n.child_base_idx),
        bits(n.primitive_base_idx),
        word(&n.child_meta[..4]),
        word(&n.child_meta[4..]),
    ]);
    for (lo, hi) in
        [(&n.child_min_x, &n.child_max_x), (&n.child_min_y, &n.child_max_y), (&n.child_min_z, &n.child_max_z)]
    {
        out.extend_from_slice(&[word(&lo[..4]), word(&lo[4..]), word(&hi[..4]), word(&hi[4..])]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{SemanticClass, Surface};

    /// The flattened words are the obvhs node's own bytes (its `repr(C)` layout, 80 bytes), and the
    /// leaf order covers every triangle once.
    #[test]
    fn nodes_flatten_to_the_obvhs_layout() {
        let mut mesh = SceneMesh::new();
        mesh.push_heightfield(
            (-8.0, -8.0),
            1.0,
            (16, 16),
            |x, y| 0.1 * x * y,
            |_, _| Surface::stuff(SemanticClass::TERRAIN),
        );
        let (words, mut order) = build(&mesh);
        let bvh2 = padded_bvh2(&mesh, pad_for(&mesh), 0.02);
        let cw = bvh2_to_cwbvh(&bvh2, MAX_LEAF, true, false);
        assert_eq!(std::mem::size_of::<CwBvhNode>(), 4 * NODE_WORDS);
        let theirs: &[u8] = bytemuck::cast_slice(&cw.nodes);
        let ours: &[u8] = bytemuck::cast_slice(&words);
        assert_eq!(ours, theirs);
        order.sort_unstable();
        assert_eq!(order, (0..mesh.len() as u32).collect::<Vec<_>>());
    }
}
