// The scene's triangles and the closest-hit triangle test, shared by both traversals: the host
// compiles this file, then a traversal (`bvh2.wgsl` or `cwbvh.wgsl`, the node bindings 0 and 1
// and `fn trace`), then `cast.wgsl` (the kernels) into one module.
//
// tris:  3 vec4 per triangle (its corners; the w of the first: the triangle's mesh index bits),
//        in the traversal's leaf order; triangle p lives in binding tris{p >> TRI_SHIFT} at
//        (p & tri mask), so a scene larger than one storage binding spans up to four.
// The test is the watertight ray/triangle test of `watertight.rs` (Woop, Benthin and Wald 2013)
// in f32 (no f64 fallback for the rare exactly-zero edge functions: such rays may pick the other
// triangle of a shared edge). Of triangles at exactly the same distance the lowest mesh index
// wins, as on the CPU, whatever order a traversal tests them in.
@group(0) @binding(2) var<storage, read> tris0: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> tris1: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> tris2: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read> tris3: array<vec4<f32>>;

// Triangles per binding as a power of two (a pipeline constant set per scene: the branches below
// fold away when the scene fits one binding).
override TRI_SHIFT: u32 = 31u;

// `trace`'s triangle for a ray that hit nothing, and for one whose traversal overflowed its stack
// (the host casts that ray on the CPU).
const MISS: u32 = 0xFFFFFFFFu;
const OVERFLOW: u32 = 0xFFFFFFFEu;

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

fn axis(v: vec3<f32>, k: u32) -> f32 {
    if (k == 0u) {
        return v.x;
    }
    if (k == 1u) {
        return v.y;
    }
    return v.z;
}

// A ray set up for the watertight test: kz the axis of the largest direction component, kx / ky
// the others (swapped to keep the winding when d[kz] < 0), shear sx, sy and scale sz.
struct TriRay {
    o: vec3<f32>,
    kx: u32,
    ky: u32,
    kz: u32,
    sx: f32,
    sy: f32,
    sz: f32,
};

fn tri_ray(o: vec3<f32>, d: vec3<f32>) -> TriRay {
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
    return TriRay(o, kx, ky, kz, axis(d, kx) * sz, axis(d, ky) * sz, sz);
}

// `a b - c d` nearly as exactly as in f64, rounded to f32: each product's rounding error from a
// fused multiply-add and the difference's from Knuth's two-sum (a device whose `fma` is not fused
// gives the plain f32 value).
fn diff_of_products(a: f32, b: f32, c: f32, d: f32) -> f32 {
    let p = a * b;
    let q = c * d;
    let ep = fma(a, b, -p);
    let eq = fma(c, d, -q);
    let s = p - q;
    let z = s - p;
    let es = (p - (s - z)) + (-q - z);
    return s + (es + (ep - eq));
}

// The closest hit so far: its distance (the ray's t_max before any) and leaf-order triangle.
struct Closest {
    t: f32,
    hit: u32,
};

// `best`, or leaf-order triangle `p` where the ray hits it closer (in (0, best.t]; at exactly
// best.t where its mesh index is lower, or nothing was hit yet).
fn closest_triangle(r: TriRay, p: u32, best: Closest) -> Closest {
    let va = corner(p, 0u) - r.o;
    let vb = corner(p, 1u) - r.o;
    let vc = corner(p, 2u) - r.o;
    let az = axis(va, r.kz);
    let bz = axis(vb, r.kz);
    let cz = axis(vc, r.kz);
    let ax = axis(va, r.kx) - r.sx * az;
    let ay = axis(va, r.ky) - r.sy * az;
    let bx = axis(vb, r.kx) - r.sx * bz;
    let by = axis(vb, r.ky) - r.sy * bz;
    let cx = axis(vc, r.kx) - r.sx * cz;
    let cy = axis(vc, r.ky) - r.sy * cz;
    var u = cx * by - cy * bx;
    var v = ax * cy - ay * cx;
    var w = bx * ay - by * ax;
    // An edge function exactly 0 in f32 (a ray through an edge or a vertex): again with the
    // products' rounding errors, as the host's f64 fallback does, so the ray goes to the triangle
    // it truly enters there too.
    if (u == 0.0 || v == 0.0 || w == 0.0) {
        u = diff_of_products(cx, by, cy, bx);
        v = diff_of_products(ax, cy, ay, cx);
        w = diff_of_products(bx, ay, by, ax);
    }
    if ((u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0)) {
        return best;
    }
    let det = u + v + w;
    if (det == 0.0) {
        return best;
    }
    let ts = u * (r.sz * az) + v * (r.sz * bz) + w * (r.sz * cz);
    var in_range = ts < 0.0 && ts >= best.t * det;
    if (det > 0.0) {
        in_range = ts > 0.0 && ts <= best.t * det;
    }
    if (!in_range) {
        return best;
    }
    let t = ts / det;
    // The closest; at exactly the same distance, the lowest mesh index (as on the CPU).
    if (t > 0.0 && (t < best.t || (t == best.t && (best.hit == MISS || triangle_id(p) < triangle_id(best.hit))))) {
        return Closest(t, p);
    }
    return best;
}
