// A traversal's nodes: NODE_VEC4S vec4 per node (pipeline constants set per scene and layout),
// node n in binding nodes{n >> NODE_SHIFT} at (n & node mask), so a BVH larger than one storage
// binding spans two. Compiled after `triangles.wgsl` and before the traversal (`bvh2.wgsl` or
// `cwbvh.wgsl`), which say what each vec4 holds.
@group(0) @binding(0) var<storage, read> nodes0: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read> nodes1: array<vec4<f32>>;

// Nodes per binding as a power of two (the branch below folds away when the scene fits one
// binding) and vec4 per node (2 for the BVH2, 5 for the CWBVH).
override NODE_SHIFT: u32 = 31u;
override NODE_VEC4S: u32 = 2u;

// Vec4 `h` of node `n`.
fn node(n: u32, h: u32) -> vec4<f32> {
    let j = NODE_VEC4S * (n & ((1u << NODE_SHIFT) - 1u)) + h;
    if ((n >> NODE_SHIFT) == 0u) {
        return nodes0[j];
    }
    return nodes1[j];
}


// The inverse direction of `d` for the traversals' slab tests: zero components replaced by a tiny
// one of the same sign (no infinities or NaN).
fn slab_inv(d: vec3<f32>) -> vec3<f32> {
    let tiny = vec3<f32>(1.0e-30);
    let d_safe = select(d, select(tiny, -tiny, d < vec3<f32>(0.0)), abs(d) < tiny);
    return 1.0 / d_safe;
}
