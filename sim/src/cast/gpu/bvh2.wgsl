// Closest hit against a binary BVH (obvhs Bvh2 node layout, flattened on the CPU), traversed with a
// fixed-size stack, nearer child first, with the watertight ray/triangle test of `watertight.rs`
// (Woop, Benthin and Wald 2013) in f32 (no f64 fallback for the rare exactly-zero edge functions:
// such rays may pick the other triangle of a shared edge). The kernels of `cast.wgsl` call
// `trace`; the host compiles this file followed by `cast.wgsl` into one module.
//
// nodes: 2 vec4 per node: (min.xyz, prim_count bits), (max.xyz, first_index bits); an inner node
//        (prim_count 0) has its children at first_index and first_index + 1, a leaf its triangles
//        at first_index .. first_index + prim_count. Node n lives in binding nodes{n >> NODE_SHIFT}
//        at (n & node mask), so a BVH larger than one storage binding spans two.
// tris:  3 vec4 per triangle (corners, w of the first: the mesh index bits), in leaf order;
//        triangle p in tris{p >> TRI_SHIFT} at (p & tri mask), up to four bindings.
// trace: (t bits, leaf-order triangle), triangle 0xFFFFFFFF: miss, 0xFFFFFFFE: the stack
//        overflowed (the host casts that ray on the CPU).
@group(0) @binding(0) var<storage, read> nodes0: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read> nodes1: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> tris0: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> tris1: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> tris2: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read> tris3: array<vec4<f32>>;

// Nodes and triangles per binding as powers of two (pipeline constants set per scene: the
// branches below fold away when the scene fits one binding).
override NODE_SHIFT: u32 = 31u;
override TRI_SHIFT: u32 = 31u;

// Half `h` (0: min and prim_count, 1: max and first_index) of node `n`.
fn node(n: u32, h: u32) -> vec4<f32> {
    let j = 2u * (n & ((1u << NODE_SHIFT) - 1u)) + h;
    if ((n >> NODE_SHIFT) == 0u) {
        return nodes0[j];
    }
    return nodes1[j];
}

// Corner `k` of leaf-order triangle `p`.
fn corner(p: u32, k: u32) -> vec3<f32> {
    let j = 3u * (p & ((1u << TRI_SHIFT) - 1u)) + k;
    switch (p >> TRI_SHIFT) {
        case 0u: {
            return tris0[j].xyz;
        }
        case 1u: {
            return tris1[j].xyz;
        }
        case 2u: {
            return tris2[j].xyz;
        }
        default: {
            return tris3[j].xyz;
        }
    }
}

// Mesh index of leaf-order triangle `p` (its first corner's fourth float).
fn triangle_id(p: u32) -> u32 {
    let j = 3u * (p & ((1u << TRI_SHIFT) - 1u));
    switch (p >> TRI_SHIFT) {
        case 0u: {
            return bitcast<u32>(tris0[j].w);
        }
        case 1u: {
            return bitcast<u32>(tris1[j].w);
        }
        case 2u: {
            return bitcast<u32>(tris2[j].w);
        }
        default: {
            return bitcast<u32>(tris3[j].w);
        }
    }
}

const STACK: u32 = 64u;
const MISS: u32 = 0xFFFFFFFFu;
const OVERFLOW: u32 = 0xFFFFFFFEu;

fn axis(v: vec3<f32>, k: u32) -> f32 {
    if (k == 0u) {
        return v.x;
    }
    if (k == 1u) {
        return v.y;
    }
    return v.z;
}

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
    var t_best = t_max;
    // Watertight test set-up: kz the largest direction component, kx / ky the others (swapped to
    // keep the winding when d[kz] < 0), shear sx, sy and scale sz.
    let a = abs(d);
    var kz = 2u;
    if (a.x >= a.y && a.x >= a.z) {
        kz = 0u;
    } else if (a.y >= a.z) {
        kz = 1u;
    }
    var kx = (kz + 1u) % 3u;
    var ky = (kx + 1u) % 3u;
    if (axis(d, kz) < 0.0) {
        let k = kx;
        kx = ky;
        ky = k;
    }
    let sz = 1.0 / axis(d, kz);
    let sx = axis(d, kx) * sz;
    let sy = axis(d, ky) * sz;
    // Slab test: zero components replaced by a tiny one of the same sign (no infinities or NaN).
    let tiny = vec3<f32>(1.0e-30);
    let d_safe = select(d, select(tiny, -tiny, d < vec3<f32>(0.0)), abs(d) < tiny);
    let inv = 1.0 / d_safe;

    var hit = MISS;
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
        if (enter(lo.xyz, hi.xyz, o, inv, t_best) < 0.0) {
            continue;
        }
        let count = bitcast<u32>(lo.w);
        let first = bitcast<u32>(hi.w);
        if (count == 0u) {
            if (sp + 2u > STACK) {
                hit = OVERFLOW;
                break;
            }
            // The children the ray enters, the nearer on top of the stack.
            let c0 = first;
            let c1 = first + 1u;
            let e0 = enter(node(c0, 0u).xyz, node(c0, 1u).xyz, o, inv, t_best);
            let e1 = enter(node(c1, 0u).xyz, node(c1, 1u).xyz, o, inv, t_best);
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
            let p = first + k;
            let va = corner(p, 0u) - o;
            let vb = corner(p, 1u) - o;
            let vc = corner(p, 2u) - o;
            let az = axis(va, kz);
            let bz = axis(vb, kz);
            let cz = axis(vc, kz);
            let ax = axis(va, kx) - sx * az;
            let ay = axis(va, ky) - sy * az;
            let bx = axis(vb, kx) - sx * bz;
            let by = axis(vb, ky) - sy * bz;
            let cx = axis(vc, kx) - sx * cz;
            let cy = axis(vc, ky) - sy * cz;
            let u = cx * by - cy * bx;
            let v = ax * cy - ay * cx;
            let w = bx * ay - by * ax;
            if ((u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0)) {
                continue;
            }
            let det = u + v + w;
            if (det == 0.0) {
                continue;
            }
            let ts = u * (sz * az) + v * (sz * bz) + w * (sz * cz);
            var in_range = ts < 0.0 && ts >= t_best * det;
            if (det > 0.0) {
                in_range = ts > 0.0 && ts <= t_best * det;
            }
            if (!in_range) {
                continue;
            }
            let t = ts / det;
            // The closest; at exactly the same distance, the lowest mesh index (as on the CPU).
            if (t > 0.0 && (t < t_best || (t == t_best && (hit == MISS || triangle_id(p) < triangle_id(hit))))) {
                t_best = t;
                hit = p;
            }
        }
    }
    return vec2<u32>(bitcast<u32>(t_best), hit);
}
