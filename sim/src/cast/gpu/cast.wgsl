// The casting kernels, compiled after a traversal file (`bvh2.wgsl`, or `cwbvh.wgsl`) that
// provides `fn trace(o, d, t_max) -> vec2<u32>` and binds the scene at bindings 0 to 5.
//
// main:       rays made on the host. input: 2 vec4 per ray: (origin.xyz, t_max), (dir.xyz, 0).
// main_beams: rays made here from a beam set kept on the device and poses per frame. input: the
//             beams, 3 vec4 each: (origin_in_sensor.xyz, t_max), (dir_in_sensor.xyz, pose bits),
//             (pose_blend, side_offset, 0, 0); then from vec4 `pose_base` on, 3 vec4 per pose: the rows of
//             the 3 x 4 `world_from_sensor` (rotation | translation), `poses` per frame, frame
//             after frame. Ray r of the call is beam (r % beams) of frame (r / beams) of the call,
//             placed by pose `pose` blended linearly toward pose `pose + 1` by `pose_blend`: its
//             origin is the blend applied to the beam's origin, its direction the blend applied
//             to the beam's direction, normalised, then turned sideways by `side_offset` (as
//             `BeamSet::ray` on the host).
// hits:       per ray of the batch (t bits, leaf-order triangle or MISS / OVERFLOW).

struct Params {
    // Rays in this batch.
    count: u32,
    // Index of the batch's first ray among the call's rays (main_beams).
    first: u32,
    // Beams per frame (main_beams).
    beams: u32,
    // Index of the first pose's vec4 in `input` (main_beams).
    pose_base: u32,
    // Poses per frame (main_beams).
    poses: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
};

@group(0) @binding(6) var<storage, read> input: array<vec4<f32>>;
@group(0) @binding(7) var<storage, read_write> hits: array<vec2<u32>>;
@group(0) @binding(8) var<uniform> params: Params;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= params.count) {
        return;
    }
    let a = input[2u * i];
    let b = input[2u * i + 1u];
    hits[i] = trace(a.xyz, b.xyz, a.w);
}

@compute @workgroup_size(64)
fn main_beams(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    if (i >= params.count) {
        return;
    }
    let r = params.first + i;
    let frame = r / params.beams;
    let beam = r - frame * params.beams;
    let a = input[3u * beam];
    let b = input[3u * beam + 1u];
    let extra = input[3u * beam + 2u];
    let blend = extra.x;
    let p = params.pose_base + 3u * (frame * params.poses + bitcast<u32>(b.w));
    var m0 = input[p];
    var m1 = input[p + 1u];
    var m2 = input[p + 2u];
    if (blend > 0.0) {
        m0 = mix(m0, input[p + 3u], blend);
        m1 = mix(m1, input[p + 4u], blend);
        m2 = mix(m2, input[p + 5u], blend);
    }
    let o = vec3<f32>(dot(m0.xyz, a.xyz) + m0.w, dot(m1.xyz, a.xyz) + m1.w, dot(m2.xyz, a.xyz) + m2.w);
    let w = vec3<f32>(dot(m0.xyz, b.xyz), dot(m1.xyz, b.xyz), dot(m2.xyz, b.xyz));
    // `w / |w|` as the host's `normalize` computes it (`w * (1 / sqrt(w . w))`): on a device whose
    // `sqrt` and division are correctly rounded, the host's rays to the bit.
    var d = w * (1.0 / sqrt(dot(w, w)));
    if (extra.y != 0.0) {
        // The host's `side = normalize_or_zero(pose * (dir x z))`, `d = normalize(d + side * offset)`.
        let cross_z = vec3<f32>(b.y, -b.x, 0.0);
        let s = vec3<f32>(dot(m0.xyz, cross_z), dot(m1.xyz, cross_z), dot(m2.xyz, cross_z));
        let rcp = 1.0 / sqrt(dot(s, s));
        var side = vec3<f32>(0.0);
        if (rcp > 0.0 && rcp < 3.0e38) {
            side = s * rcp;
        }
        let turned = d + side * extra.y;
        d = turned * (1.0 / sqrt(dot(turned, turned)));
    }
    hits[i] = trace(o, d, a.w);
}
