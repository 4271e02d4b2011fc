// Closest hit against a compressed 8-wide BVH (CWBVH, Ylitie, Karras and Laine 2017: "Efficient
// incoherent ray traversal on GPUs through compressed wide BVHs"; obvhs `CwBvhNode` layout,
// converted from the BVH2 on the CPU), traversed with a stack of node groups, children in the
// order of the ray's octant. The triangles, their bindings and the watertight test are in
// `triangles.wgsl` and the node bindings in `nodes.wgsl` (compiled before this file); the kernels of `cast.wgsl` (after it) call `trace`.
//
// nodes: 5 vec4 (80 bytes) per node, read as u32 where not floats:
//        0: (p.xyz: the node box's min corner, e bits: exponents ex | ey << 8 | ez << 16 and imask << 24)
//        1: (child_base: first child node, prim_base: first leaf-order triangle, meta of children
//            0..3, meta of children 4..7; a byte per child)
//        2, 3, 4: the children's quantized boxes on x, y, z: (min of children 0..3, of 4..7,
//            max of children 0..3, of 4..7), a byte per child.
//        Child i's box on axis a is p.a + q * 2^(e_a - 127) for its bytes q (the builder rounds
//        outward, and every triangle box was padded: the test below is conservative).
//        imask bit i: child i is an inner node. Its meta byte: 0 for an empty slot; an inner
//        child 0b001_11sss (24 + its slot s), its node at child_base + the inner children in
//        slots below s; a leaf 0bccc_ooooo, its triangles at prim_base + o (o < 24), as many as
//        the unary c (001: 1, 011: 2, 111: 3).
//        `node(n, h)` of `nodes.wgsl` (NODE_VEC4S = 5) is vec4 h of node n.
// Hit masks (32 bits) of a node: bits 24..31 the inner children hit, at bit 24 + (slot ^ oct_inv)
// where oct_inv is the octant of -d (the builder put the nearest child for octant o in slot o,
// so the highest bit is the nearest child); bits 0..23 the triangles of the leaves hit, at their
// offset from prim_base.
// A group (u32 pair): (child_base, inner hit bits | imask) or (prim_base, triangle bits).
// trace: (t bits, leaf-order triangle), triangle MISS: nothing hit, OVERFLOW: the stack
//        overflowed (the host casts that ray on the CPU).
// Groups on the stack at most (a group per level of the tree: the BVH8's depth).
const STACK: u32 = 32u;

// The four bytes of `w`, low first.
fn bytes4(w: u32) -> vec4<u32> {
    return (vec4<u32>(w) >> vec4<u32>(0u, 8u, 16u, 24u)) & vec4<u32>(0xffu);
}

// Hit mask bits (see above) of four children: `info` their meta bytes, `lo` / `hi` their
// quantized boxes' min and max words per axis, `scale` and `off` the node's grid in ray
// distance per axis (t = q * scale + off).
fn hit_bits(
    info: u32,
    lo: vec3<u32>,
    hi: vec3<u32>,
    scale: vec3<f32>,
    off: vec3<f32>,
    oct_inv: u32,
    t_best: f32,
) -> u32 {
    let tx0 = vec4<f32>(bytes4(lo.x)) * scale.x + off.x;
    let tx1 = vec4<f32>(bytes4(hi.x)) * scale.x + off.x;
    let ty0 = vec4<f32>(bytes4(lo.y)) * scale.y + off.y;
    let ty1 = vec4<f32>(bytes4(hi.y)) * scale.y + off.y;
    let tz0 = vec4<f32>(bytes4(lo.z)) * scale.z + off.z;
    let tz1 = vec4<f32>(bytes4(hi.z)) * scale.z + off.z;
    let near = max(max(min(tx0, tx1), min(ty0, ty1)), max(min(tz0, tz1), vec4<f32>(0.0)));
    let far = min(min(max(tx0, tx1), max(ty0, ty1)), min(max(tz0, tz1), vec4<f32>(t_best)));
    let m = bytes4(info);
    // Inner children have both bits 3 and 4 of their meta set (24..31); leaves (offsets < 24) never.
    let inner = (m & (m << vec4<u32>(1u)) & vec4<u32>(0x10u)) != vec4<u32>(0u);
    let index = select(m, m ^ vec4<u32>(oct_inv), inner) & vec4<u32>(0x1fu);
    // An inner child's bits are 001 (one bit), a leaf's its unary triangle count, empty slots 0.
    let bits = select(vec4<u32>(0u), (m >> vec4<u32>(5u)) & vec4<u32>(7u), near <= far) << index;
    return bits.x | bits.y | bits.z | bits.w;
}

// Closest hit of the ray `o + t d` (`d` unit length, `t` in [0, t_max]): (t bits, leaf-order
// triangle), triangle MISS or OVERFLOW as in the layout notes above.
fn trace(o: vec3<f32>, d: vec3<f32>, t_max: f32) -> vec2<u32> {
    let r = tri_ray(o, d);
    var best = Closest(t_max, MISS);
    let inv = slab_inv(d);
    // The octant of -d: 4 for x >= 0, 2 for y, 1 for z.
    let oct_inv = select(0u, 4u, !(d.x < 0.0)) | select(0u, 2u, !(d.y < 0.0)) | select(0u, 1u, !(d.z < 0.0));

    var stack: array<vec2<u32>, 32>;
    var sp = 0u;
    // The root as a group of one inner child: bit 31 is slot 7 ^ oct_inv, no inner slots below it.
    var nodes = vec2<u32>(0u, 0x80000000u);
    var tris = vec2<u32>(0u, 0u);
    loop {
        // The triangles of the leaves hit in the node last entered.
        while (tris.y != 0u) {
            let k = firstTrailingBit(tris.y);
            tris.y = tris.y & (tris.y - 1u);
            best = closest_triangle(r, tris.x + k, best);
        }
        if ((nodes.y & 0xff000000u) == 0u) {
            if (sp == 0u) {
                break;
            }
            sp = sp - 1u;
            nodes = stack[sp];
        }
        // The nearest child left in the group; the rest stays on the stack.
        let bit = firstLeadingBit(nodes.y);
        nodes.y = nodes.y & ~(1u << bit);
        let slot = (bit - 24u) ^ oct_inv;
        let n = nodes.x + countOneBits(nodes.y & ((1u << slot) - 1u));
        if ((nodes.y & 0xff000000u) != 0u) {
            if (sp == STACK) {
                best.hit = OVERFLOW;
                break;
            }
            stack[sp] = nodes;
            sp = sp + 1u;
        }
        let a = node(n, 0u);
        let b = bitcast<vec4<u32>>(node(n, 1u));
        let qx = bitcast<vec4<u32>>(node(n, 2u));
        let qy = bitcast<vec4<u32>>(node(n, 3u));
        let qz = bitcast<vec4<u32>>(node(n, 4u));
        let eb = bitcast<u32>(a.w);
        // 2^(e - 127) per axis: the exponent bytes placed in a float's exponent field.
        let ext = bitcast<vec3<f32>>(((vec3<u32>(eb) >> vec3<u32>(0u, 8u, 16u)) & vec3<u32>(0xffu)) << vec3<u32>(23u));
        let scale = ext * inv;
        let off = (a.xyz - o) * inv;
        let hits = hit_bits(b.z, vec3<u32>(qx.x, qy.x, qz.x), vec3<u32>(qx.z, qy.z, qz.z), scale, off, oct_inv, best.t)
            | hit_bits(b.w, vec3<u32>(qx.y, qy.y, qz.y), vec3<u32>(qx.w, qy.w, qz.w), scale, off, oct_inv, best.t);
        nodes = vec2<u32>(b.x, (hits & 0xff000000u) | (eb >> 24u));
        tris = vec2<u32>(b.y, hits & 0x00ffffffu);
    }
    return vec2<u32>(bitcast<u32>(best.t), best.hit);
}
