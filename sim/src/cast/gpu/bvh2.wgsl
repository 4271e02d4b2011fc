// Closest hit against a binary BVH (obvhs Bvh2 node layout, flattened on the CPU), traversed with a
// fixed-size stack, nearer child first. The triangles, their bindings and the watertight test are
// in `triangles.wgsl` and the node bindings in `nodes.wgsl` (compiled before this file); the
// kernels of `cast.wgsl` (after it) call `trace`.
//
// nodes: 2 vec4 per node: (min.xyz, prim_count bits), (max.xyz, first_index bits); an inner node
//        (prim_count 0) has its children at first_index and first_index + 1, a leaf its triangles
//        at first_index .. first_index + prim_count. `node(n, h)` of
//        `nodes.wgsl` (NODE_VEC4S = 2) is half h (0: min and prim_count, 1: max and first_index).
// trace: (t bits, leaf-order triangle), triangle MISS: nothing hit, OVERFLOW: the stack
//        overflowed (the host casts that ray on the CPU).
const STACK: u32 = 64u;

// Entry distance (>= 0) of the ray into a node's box within t_best, or -1 when it misses.
fn enter(lo: vec3<f32>, hi: vec3<f32>, o: vec3<f32>, inv: vec3<f32>, t_best: f32) -> f32 {
    let t0 = (lo - o) * inv;
    let t1 = (hi - o) * inv;
    let tmin = max(max(min(t0.x, t1.x), min(t0.y, t1.y)), max(min(t0.z, t1.z), 0.0));
    let tmax = min(min(max(t0.x, t1.x), max(t0.y, t1.y)), min(max(t0.z, t1.z), t_best));
    return select(-1.0, tmin, tmin <= tmax);
}

// Closest hit of the ray `o + t d` (`d` unit length, `t` in [0, t_max]): (t bits, leaf-order
// triangle), triangle MISS or OVERFLOW as in the layout notes above.
fn trace(o: vec3<f32>, d: vec3<f32>, t_max: f32) -> vec2<u32> {
    let r = tri_ray(o, d);
    var best = Closest(t_max, MISS);
    let inv = slab_inv(d);

    var stack: array<u32, 64>;
    var sp = 1u;
    stack[0] = 0u;
    loop {
        if (sp == 0u) {
            break;
        }
        sp = sp - 1u;
        let n = stack[sp];
        let lo = node(n, 0u);
        let hi = node(n, 1u);
        // A box entered beyond a hit found since it was pushed is skipped.
        if (enter(lo.xyz, hi.xyz, o, inv, best.t) < 0.0) {
            continue;
        }
        let count = bitcast<u32>(lo.w);
        let first = bitcast<u32>(hi.w);
        if (count == 0u) {
            if (sp + 2u > STACK) {
                best.hit = OVERFLOW;
                break;
            }
            // The children the ray enters, the nearer on top of the stack.
            let c0 = first;
            let c1 = first + 1u;
            let e0 = enter(node(c0, 0u).xyz, node(c0, 1u).xyz, o, inv, best.t);
            let e1 = enter(node(c1, 0u).xyz, node(c1, 1u).xyz, o, inv, best.t);
            if (e0 >= 0.0 && e1 >= 0.0) {
                if (e0 <= e1) {
                    stack[sp] = c1;
                    stack[sp + 1u] = c0;
                } else {
                    stack[sp] = c0;
                    stack[sp + 1u] = c1;
                }
                sp = sp + 2u;
            } else if (e0 >= 0.0) {
                stack[sp] = c0;
                sp = sp + 1u;
            } else if (e1 >= 0.0) {
                stack[sp] = c1;
                sp = sp + 1u;
            }
            continue;
        }
        for (var k = 0u; k < count; k = k + 1u) {
            best = closest_triangle(r, first + k, best);
        }
    }
    return vec2<u32>(bitcast<u32>(best.t), best.hit);
}
