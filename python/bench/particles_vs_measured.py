#!/usr/bin/env python3
"""Our snowfall and rain side by side with real measurements (shares of returns, by range and by
beam elevation).

    python particles_vs_measured.py [--bin target/quick/groundtruth] [--frames 5] [--seeds 0 1]
                                    [--snow 1 3] [--rain 2 10] [--scene rural] [--rig os1-128-roof]

Runs the built ``groundtruth`` binary (``scan --format pcd``, our organized PCD with ``label`` and
``range``) on the scene, moving at 10 m/s, in snow and rain of each rate, and reports for each:

* ``share``: particles (label 152 snow, 151 rain) among all returns of the frames;
* ``median_m``, ``below_3m``, ``beyond_14m``: where the particles lie;
* ``by_range``: the particles' share of all returns in 2 m range bins (2-4, 4-6, 6-8, 8-10 m);
* ``by_elevation``: the particles' share of the returns of beams in elevation bins (degrees,
  sensor frame: the point's height above the sensor's mount over its range);
* ``intensity``: 5/50/95 % of the particles' intensities (0..1).

The measurements it is read beside (``docs/weather.md``, "Calibrated on measurements"):

* snow: WADS (Kurup and Bos 2021, "DSOR: a scalable statistical filter for removing falling
  snow from LiDAR point clouds in severe winter weather", arXiv:2109.07078; the labelled
  recordings, falling snow = label 110): flakes 4.7-8.4 % of the unique returns of a frame
  (6.7 % on average), median range 6.5-6.9 m, almost none closer than 3 m, under 1 % beyond
  14 m; by range 76 % of returns at 2-4 m, 70 % at 4-6, 45 % at 6-8, 13 % at 8-10; near-horizontal
  beams 11.5 %, beams below -6 deg 0.9 % (figures of issue 45, measured on the public labels);
* rain: Linnhoff et al. 2022 (docs/weather.md; the per-beam comparison is
  ``rain_vs_measured.py``).

Prints one JSON object.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

RAIN, SNOW = 151, 152
# Our organized PCD's record (sim/src/io/pcd/writer.rs, WRITE_FIELDS), packed little-endian.
RECORD = np.dtype(
    [
        ("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("intensity", "<f4"), ("ring", "<u2"), ("time", "<f8"),
        ("label", "<u4"), ("instance", "<u4"), ("ground", "u1"), ("range", "<f4"), ("sensor", "u1"),
        ("echo", "u1"), ("column", "<u4"), ("nx", "<f4"), ("ny", "<f4"), ("nz", "<f4"),
    ]
)
# Mount height of the roof rigs (sim/src/rig/presets.rs): the OS1's at z 1.85 m.
MOUNT_Z_M = 1.85
RANGE_BINS_M = [(0, 2), (2, 4), (4, 6), (6, 8), (8, 10), (10, 14), (14, 1e9)]
ELEVATION_BINS_DEG = [(-90, -6), (-6, -2), (-2, 2), (2, 6), (6, 90)]


def read_cells(path: Path) -> np.ndarray:
    """Every cell of one organized PCD of ours, no-return cells (NaN x) included."""
    data = path.read_bytes()
    end = data.index(b"DATA binary\n") + len(b"DATA binary\n")
    return np.frombuffer(data[end:], dtype=RECORD)


def read_pcd(path: Path) -> np.ndarray:
    """The returns of one organized PCD of ours (no-return cells, NaN x, dropped)."""
    rec = read_cells(path)
    return rec[np.isfinite(rec["x"])]


def scan(
    binary: str, scene: str, rig: str, weather: str, seed: int, frames: int, out: Path,
    speed_m_per_s: float = 10.0, cells: bool = False,
) -> np.ndarray:
    """All returns of a scan (every frame) as one record array; every cell when ``cells``."""
    cmd = [
        binary, "scan", "--scene", scene, "--rig", rig, "--seed", str(seed), "--frames", str(frames),
        "--speed-m-per-s", f"{speed_m_per_s:g}", "--weather", weather, "--format", "pcd", "--out", str(out),
    ]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    read = read_cells if cells else read_pcd
    return np.concatenate([read(p) for p in sorted(out.glob("*.pcd"))])


def stats(points: np.ndarray, label: int) -> dict:
    """The particles' share of the returns overall, by range and by elevation, and where they lie."""
    is_p = points["label"] == label
    r = points["range"]
    elevation = np.degrees(np.arcsin(np.clip((points["z"] - MOUNT_Z_M) / np.maximum(r, 1e-3), -1, 1)))
    rp = r[is_p]

    def share(mask: np.ndarray) -> float | None:
        n = int(mask.sum())
        return round(100.0 * float(is_p[mask].sum()) / n, 2) if n else None

    return {
        "returns": int(len(points)),
        "share": share(np.ones_like(is_p)),
        "median_m": round(float(np.median(rp)), 2) if len(rp) else None,
        "below_3m": round(100.0 * float((rp < 3).mean()), 2) if len(rp) else None,
        "beyond_14m": round(100.0 * float((rp > 14).mean()), 2) if len(rp) else None,
        "by_range": {f"{a}-{b if b < 1e9 else 'inf'}": share((r >= a) & (r < b)) for a, b in RANGE_BINS_M},
        "by_elevation": {f"{a}..{b}": share((elevation >= a) & (elevation < b)) for a, b in ELEVATION_BINS_DEG},
        "intensity": [round(float(q), 4) for q in np.percentile(points["intensity"][is_p], [5, 50, 95])]
        if len(rp)
        else None,
    }


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default="target/quick/groundtruth")
    ap.add_argument("--scene", default="rural")
    ap.add_argument("--rig", default="os1-128-roof")
    ap.add_argument("--seeds", type=int, nargs="+", default=[0, 1])
    ap.add_argument("--frames", type=int, default=3)
    ap.add_argument("--snow", type=float, nargs="*", default=[1.0, 3.0])
    ap.add_argument("--rain", type=float, nargs="*", default=[2.0, 10.0])
    args = ap.parse_args()
    result = {"scene": args.scene, "rig": args.rig, "seeds": args.seeds, "frames": args.frames}
    with tempfile.TemporaryDirectory() as tmp:
        for kind, label, rates in (("snow", SNOW, args.snow), ("rain", RAIN, args.rain)):
            for rate in rates:
                spec = f"{kind}:rate_mm_h={rate:g}"
                pts = np.concatenate(
                    [
                        scan(args.bin, args.scene, args.rig, spec, s, args.frames, Path(tmp) / f"{spec}-{s}")
                        for s in args.seeds
                    ]
                )
                result[spec] = stats(pts, label)
    json.dump(result, sys.stdout, indent=1)
    print()
    return 0


if __name__ == "__main__":
    sys.exit(main())
