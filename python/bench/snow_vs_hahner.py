#!/usr/bin/env python3
"""Our per-beam snowfall side by side with Hahner et al.'s published snowfall model (CVPR 2022).

    python snow_vs_hahner.py --snow-sim PATH/TO/LiDAR_snow_sim [--scene city] [--seed 0]
                             [--rates 0.5 2.0] [--cache DIR]

Scans the scene with the HDL-64E roof rig in clear air (``weather="clear"``) and in snow of each
rate (mm/h of water), applies the authors' own code (``tools/snowfall/simulation.augment`` of a
checkout of github.com/SysCV/LiDAR_snow_sim, imported, never copied) to the clear scan at the
same rate, and compares the share of the clear scan's returns that became snow returns (theirs:
label 2, "scattered"; ours: cells labelled snow, 152), the share lost, and where the snow
returns lie.

The authors' model needs, besides the clear cloud with intensities on 0..255:
- a channel per point (their STF HDL-64E S3 calibration's laser, ``calib/20171102_64E_S3.yaml``):
  the laser whose vertical angle is nearest the point's elevation;
- 64 files of snowflakes per channel plane (disks in a 2-D plane of radius 80 m), which the
  authors ship as a 2.3 GB download: made here with their ``tools/snowfall/sampling.dart_throwing``
  as their ``sampling.py`` does, seeded, cached in ``--cache``;
- the terminal velocity their ``precompute.py`` pairs with each rate (0.5 -> 2.0 m/s, 1 -> 1.6,
  1.5 -> 0.6, 2 -> 2.0, 2.5 -> 1.6), Gunn-Marshall sizes, a 3 mrad beam divergence, noise floor
  0.7 and the full 360 deg (their camera-FOV filter off).
It needs numpy, scipy, scikit-learn 1.1 (its RANSAC's ``loss='squared_loss'``; newer releases
silently fall back to a flat ground plane), PyYAML, tqdm and matplotlib beside ``groundtruth``.
About a minute per rate (their per-beam loops are Python). Prints one JSON object.
"""

from __future__ import annotations

import argparse
import json
import random
import sys
from pathlib import Path

import numpy as np

import groundtruth as gt

SNOW = 152
# The terminal velocities the authors' precompute.py pairs with each snowfall rate (m/s).
PRECOMPUTE_PAIRS = {0.5: 2.0, 1.0: 1.6, 1.5: 0.6, 2.0: 2.0, 2.5: 1.6}


def channels(snow_sim: Path, xyz: np.ndarray) -> np.ndarray:
    """The STF HDL-64E S3 laser nearest each point's elevation."""
    import yaml  # noqa: PLC0415

    calib = yaml.safe_load(open(snow_sim / "calib" / "20171102_64E_S3.yaml"))
    vert = np.array([laser["vert_correction"] for laser in calib["lasers"]])
    elevation = np.arctan2(xyz[:, 2], np.linalg.norm(xyz[:, :2], axis=1))
    return np.abs(elevation[:, None] - vert[None, :]).argmin(axis=1).astype(np.float64)


def flakes(sampling, root: Path, prefix: str, rain_rate: float, occupancy: float, seed: int, empty: bool) -> None:
    """The 64 snowflake planes ``augment`` loads, made once per (rate, seed)."""
    d = root / "training" / "snowflakes" / "npy"
    d.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(seed)
    for k in range(1, 65):
        f = d / f"{prefix}_{k}.npy"
        if not f.exists():
            disks = np.zeros((0, 3)) if empty else sampling.dart_throwing(
                occupancy_ratio=occupancy, precipitation_rate=rain_rate, R_0=80.0, rng=rng, distribution="gunn"
            )
            np.save(f, disks)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--snow-sim", required=True, type=Path, help="checkout of SysCV/LiDAR_snow_sim")
    ap.add_argument("--scene", default="city")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--rates", type=float, nargs="+", default=[0.5, 2.0], choices=sorted(PRECOMPUTE_PAIRS))
    ap.add_argument("--cache", type=Path, default=Path("target/snowflakes"))
    args = ap.parse_args()
    sys.path.insert(0, str(args.snow_sim.resolve()))
    from tools.snowfall import sampling, simulation  # noqa: PLC0415  (the authors' modules)

    rig = "hdl64e-roof"
    clear = gt.scan(args.scene, rig, seed=args.seed, weather="clear")[0]
    valid = clear.valid.ravel()
    cells = np.nonzero(valid)[0]
    sensor_from_vehicle = np.linalg.inv(clear.vehicle_from_sensor(0).astype(np.float64))
    xyz = clear.xyz.reshape(-1, 3)[valid].astype(np.float64) @ sensor_from_vehicle[:3, :3].T + sensor_from_vehicle[:3, 3]
    intensity = np.round(clear.intensity.ravel()[valid].astype(np.float64) * 255.0)
    r0 = np.linalg.norm(xyz, axis=1)
    n = len(cells)
    cloud = np.column_stack([xyz, intensity, channels(args.snow_sim, xyz), np.arange(n, dtype=np.float64)])
    bands = [(0, 10), (10, 20), (20, 40), (40, 80), (80, 200)]

    rows = []
    for rate in args.rates:
        v = PRECOMPUTE_PAIRS[rate]
        rain_rate = sampling.snowfall_rate_to_rainfall_rate(rate, v)
        occupancy = sampling.compute_occupancy(rate, v)
        prefix = f"gunn_{rain_rate}_{occupancy}"
        root = args.cache.resolve() / f"seed{args.seed}"
        flakes(sampling, root, prefix, rain_rate, occupancy, args.seed, empty=False)
        random.seed(args.seed)
        np.random.seed(args.seed)
        (_, removed, _), out = simulation.augment(
            pc=cloud.copy(), particle_file_prefix=prefix, beam_divergence=float(np.degrees(3e-3)), shuffle=True,
            show_progressbar=False, only_camera_fov=False, noise_floor=0.7, root_path=str(root),
        )
        label = np.full(n, -1)
        label[out[:, 5].astype(np.int64)] = out[:, 4].astype(np.int64)  # -1 removed, 2 snow return
        theirs = label == 2
        theirs_ranges = np.linalg.norm(out[out[:, 4] == 2, :3], axis=1)

        snow = gt.scan(args.scene, rig, seed=args.seed, weather=f"snow:rate_mm_h={rate}")[0]
        ours = snow.valid.ravel()[cells] & (snow.label.ravel()[cells] == SNOW)
        ours_ranges = snow.range.ravel()[cells][ours]
        pct = lambda r: np.percentile(r, [5, 50, 95]).round(2).tolist() if len(r) else None  # noqa: E731
        rows.append(
            {
                "rate_mm_h": rate,
                "their_terminal_velocity_m_s": v,
                "clear_returns": n,
                "share_theirs": float(theirs.mean()),
                "share_ours": float(ours.mean()),
                "ratio_ours_to_theirs": float(ours.mean() / theirs.mean()) if theirs.any() else None,
                "lost_theirs": float((label == -1).mean()),
                "lost_ours": float((~snow.valid.ravel()[cells]).mean()),
                "snow_range_m_5_50_95": {"theirs": pct(theirs_ranges), "ours": pct(ours_ranges)},
                "share_by_clear_range_m": {
                    f"{a}-{b}": {
                        "theirs": float(theirs[(r0 >= a) & (r0 < b)].mean()) if ((r0 >= a) & (r0 < b)).any() else None,
                        "ours": float(ours[(r0 >= a) & (r0 < b)].mean()) if ((r0 >= a) & (r0 < b)).any() else None,
                    }
                    for a, b in bands
                },
                "ours_snow_on_beams_without_clear_return": int(
                    (~valid & snow.valid.ravel() & (snow.label.ravel() == SNOW)).sum()
                ),
                "their_removed_by_noise_floor": int(removed),
            }
        )
    print(json.dumps({"scene": args.scene, "rig": rig, "seed": args.seed, "snow": rows}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
