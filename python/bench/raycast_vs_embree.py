"""Side by side: `groundtruth bench raycast` (our BvhCaster) against Open3D's RaycastingScene
(Embree) on the same mesh and the same rays, interleaved, several rounds; prints one JSON.

Data (written once into --work):
  - the fixture terrain (1.3 M triangles) as PLY, by `groundtruth scene export --scene fixture-terrain`;
  - coherent rays: the fixture LiDAR (128 x 2048, elevations -22.5..22.5 deg, azimuth from +180 deg
    clockwise), 16 frames moving 1 m along +x, ring-major (each ring's 2048 azimuths in turn), from
    `sensor_origin(frame)` of `sim/src/cast/fixture.rs`;
  - incoherent rays: the same origins, directions uniform on the sphere (seeded), same count.
  Ray files are raw little-endian f32 records `ox oy oz dx dy dz`.

Usage:
  python3 python/bench/raycast_vs_embree.py --bin target/quick/groundtruth --threads 2 --rounds 5
  (needs `pip install open3d numpy`; on Debian Open3D also needs libusb-1.0-0.)
"""

import argparse
import json
import os
import statistics
import subprocess
import time

import numpy as np

ROWS, COLS, HALF_FOV_DEG, SENSOR_HEIGHT_M = 128, 2048, 22.5, 1.9


def terrain_height_m(x, y):
    """`fixture::terrain_height_m`, in float32."""
    x, y = np.float32(x), np.float32(y)
    return (
        np.float32(3.0) * np.sin(x / np.float32(37.0)) * np.cos(y / np.float32(53.0))
        + np.float32(1.2) * np.sin(x / np.float32(13.0) + y / np.float32(17.0))
        + np.float32(0.02) * x
    )


def coherent_rays(frames):
    """The fixture LiDAR's rays, `frames` frames, ring-major: shape (frames * ROWS * COLS, 6)."""
    row = np.arange(ROWS, dtype=np.float32)
    col = np.arange(COLS, dtype=np.float32)
    el = np.deg2rad(-HALF_FOV_DEG + 2.0 * HALF_FOV_DEG * row / (ROWS - 1)).astype(np.float32)
    az = (np.float32(np.pi) - np.float32(2 * np.pi) * col / COLS).astype(np.float32)
    el, az = np.meshgrid(el, az, indexing="ij")  # (ROWS, COLS): ring-major
    d = np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], axis=-1).reshape(-1, 3)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    out = []
    for f in range(frames):
        x = np.float32(f)
        o = np.array([x, 0.0, terrain_height_m(x, 0.0) + np.float32(SENSOR_HEIGHT_M)], dtype=np.float32)
        out.append(np.hstack([np.broadcast_to(o, d.shape), d]))
    return np.vstack(out).astype(np.float32)


def incoherent_rays(coherent, seed):
    """The same origins, directions uniform on the unit sphere (seeded)."""
    rng = np.random.default_rng(seed)
    d = rng.normal(size=(len(coherent), 3)).astype(np.float32)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    return np.hstack([coherent[:, :3], d]).astype(np.float32)


def ours(bin_path, mesh, rays_file, threads):
    """One `bench raycast` run: M rays/s and hit count."""
    cmd = [bin_path, "bench", "raycast", "--mesh", mesh, "--rays", rays_file, "--frames", "1",
           "--threads", str(threads)]
    j = json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)
    return j["rays_per_s"] / 1e6, j["hits"]


def embree(scene, rays_tensor, threads):
    """One Open3D cast of all rays: M rays/s and hit count."""
    t0 = time.perf_counter()
    r = scene.cast_rays(rays_tensor, nthreads=threads)
    dt = time.perf_counter() - t0
    hits = int(np.isfinite(r["t_hit"].numpy()).sum())
    return rays_tensor.shape[0] / dt / 1e6, hits


def summary(xs):
    return {"min": round(min(xs), 3), "median": round(statistics.median(xs), 3), "max": round(max(xs), 3)}


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--bin", default="target/quick/groundtruth", help="groundtruth binary")
    p.add_argument("--work", default="/tmp/raycast-vs-embree", help="folder for the mesh and ray files")
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--rounds", type=int, default=5)
    p.add_argument("--frames", type=int, default=16)
    p.add_argument("--seed", type=int, default=46)
    a = p.parse_args()

    import open3d as o3d

    os.makedirs(a.work, exist_ok=True)
    mesh_path = os.path.join(a.work, "fixture-terrain.ply")
    if not os.path.exists(mesh_path):
        subprocess.run([a.bin, "scene", "export", "--scene", "fixture-terrain", "--out", mesh_path], check=True,
                       capture_output=True)
    coherent = coherent_rays(a.frames)
    sets = {"coherent": coherent, "incoherent": incoherent_rays(coherent, a.seed)}
    files = {}
    for name, rays in sets.items():
        files[name] = os.path.join(a.work, f"{name}-{a.frames}.rays")
        rays.astype("<f4").tofile(files[name])

    m = o3d.t.io.read_triangle_mesh(mesh_path)
    verts = o3d.core.Tensor(m.vertex.positions.numpy().astype(np.float32))
    tris = o3d.core.Tensor(m.triangle.indices.numpy().astype(np.uint32))
    scene = o3d.t.geometry.RaycastingScene(nthreads=a.threads)
    scene.add_triangles(verts, tris)
    scene.cast_rays(o3d.core.Tensor(coherent[:1024]), nthreads=a.threads)  # Builds the BVH (lazily).

    out = {"threads": a.threads, "rounds": a.rounds, "triangles": int(tris.shape[0]),
           "open3d": o3d.__version__, "bin": a.bin, "loadavg_before": os.getloadavg()[0]}
    for name, rays in sets.items():
        tensor = o3d.core.Tensor(rays)
        mine, theirs, ratio = [], [], []
        for _ in range(a.rounds):
            m_rate, m_hits = ours(a.bin, mesh_path, files[name], a.threads)
            e_rate, e_hits = embree(scene, tensor, a.threads)
            mine.append(m_rate)
            theirs.append(e_rate)
            ratio.append(m_rate / e_rate)
        out[name] = {"rays": len(rays), "ours_M_rays_per_s": summary(mine), "embree_M_rays_per_s": summary(theirs),
                     "ratio": summary(ratio), "hits_ours": m_hits, "hits_embree": e_hits}
    out["loadavg_after"] = os.getloadavg()[0]
    print(json.dumps(out))


if __name__ == "__main__":
    main()
