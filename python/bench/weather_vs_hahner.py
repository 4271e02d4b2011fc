#!/usr/bin/env python3
"""Our per-beam fog side by side with Hahner et al.'s published fog model (ICCV 2021).

    python weather_vs_hahner.py --fog-sim PATH/TO/LiDAR_fog_sim [--scene city] [--rig hdl64e-roof]
                                [--seeds 0 1 2] [--visibility 50 150]

For each seed it scans the scene twice with the same rig and seed: once in clear air
(``weather="clear"``: the sensor's detection threshold, no medium) and once in fog of the given
visibility. It then applies the authors' own code (``fog_simulation.simulate_fog`` of a checkout of
github.com/MartinHahner/LiDAR_fog_sim, imported, never copied) to the clear scan, at the same
attenuation ``alpha = ln 20 / V`` and ``beta = 0.046 / V`` (the paper's values, as the authors'
viewer sets them), with intensities on its 0..255 scale, and compares:

* ``share``: of the beams that return in clear air, the share whose return became a fog return
  (theirs: ``simulate_fog``'s fog responses; ours: cells labelled fog, 150);
* ours only: fog returns on beams that return nothing in clear air (a post-processing of finished
  clouds cannot make them) and hard returns lost below the detection threshold.

Prints one JSON object. Needs numpy, scipy and tqdm (the fog code's imports) beside ``groundtruth``.
"""

from __future__ import annotations

import argparse
import copy
import json
import sys
from pathlib import Path

import numpy as np

import groundtruth as gt

FOG = 150


def sensor_points(frame: gt.Frame, rounded: bool) -> tuple[np.ndarray, np.ndarray]:
    """The returns of ``frame`` in the sensor frame with intensities ×255 (rounded to integers as
    a sensor's 8-bit intensities are, if ``rounded``), and their flat cell indices."""
    valid = frame.valid.ravel()
    xyz = frame.xyz.reshape(-1, 3)[valid].astype(np.float64)
    sensor_from_vehicle = np.linalg.inv(frame.vehicle_from_sensor(0).astype(np.float64))
    xyz = xyz @ sensor_from_vehicle[:3, :3].T + sensor_from_vehicle[:3, 3]
    i = frame.intensity.ravel()[valid].astype(np.float64) * 255.0
    if rounded:
        i = np.round(i)
    return np.column_stack([xyz, i]), np.nonzero(valid)[0]


def hahner(fs, cloud: np.ndarray, visibility_m: float) -> tuple[np.ndarray, np.ndarray]:
    """Per point: whether the authors' model turns it into a fog return, and its output intensity
    (0..255)."""
    p = fs.ParameterSet(alpha=float(np.log(20) / visibility_m), gamma=1e-6)
    # ParameterSet derives mor/beta from its default alpha before applying kwargs; recompute them
    # for this visibility as the authors' viewer does (the paper's beta = 0.046 / MOR).
    p.mor = np.log(20) / p.alpha
    p.beta = 0.046 / p.mor
    p.beta_0 = p.gamma / np.pi
    hard = fs.P_R_fog_hard(p, copy.deepcopy(cloud))
    out, _, info = fs.simulate_fog(p, copy.deepcopy(cloud), 0, False, "v1")
    flag = np.any(out != hard, axis=1)
    assert int(flag.sum()) == (int(info["num_fog_responses"]) if info else 0)
    return flag, out[:, 3]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--fog-sim", required=True, type=Path, help="checkout of MartinHahner/LiDAR_fog_sim")
    ap.add_argument("--scene", default="city")
    ap.add_argument("--rig", default="hdl64e-roof")
    ap.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2])
    ap.add_argument("--visibility", type=float, nargs="+", default=[50.0, 150.0])
    ap.add_argument(
        "--rounded",
        action="store_true",
        help="round the intensities to integers 0..255 first, as 8-bit sensor data are (then returns dimmer "
        "than 0.5/255 enter as 0 and can never become fog in their model)",
    )
    args = ap.parse_args()
    sys.path.insert(0, str(args.fog_sim.resolve()))
    import fog_simulation as fs  # noqa: PLC0415  (the authors' module, from their checkout)

    rows = []
    for v in args.visibility:
        acc = {"clear_returns": 0, "theirs": 0, "ours": 0, "ours_from_no_return": 0, "ours_lost": 0}
        ranges_theirs, ranges_ours, fog_intensity = [], [], []
        for seed in args.seeds:
            clear = gt.scan(args.scene, args.rig, seed=seed, weather="clear")[0]
            fog = gt.scan(args.scene, args.rig, seed=seed, weather=f"fog:visibility_m={v}")[0]
            cloud, cells = sensor_points(clear, args.rounded)
            theirs, intensity = hahner(fs, cloud, v)
            fog_intensity.append(intensity[theirs])
            label = fog.label.ravel()
            fog_valid = fog.valid.ravel()
            ours = fog_valid[cells] & (label[cells] == FOG)
            r0 = np.linalg.norm(cloud[:, :3], axis=1)
            acc["clear_returns"] += len(cells)
            acc["theirs"] += int(theirs.sum())
            acc["ours"] += int(ours.sum())
            acc["ours_lost"] += int((~fog_valid[cells]).sum())
            no_return = ~clear.valid.ravel()
            acc["ours_from_no_return"] += int((no_return & fog_valid & (label == FOG)).sum())
            ranges_theirs.append(r0[theirs])
            ranges_ours.append(r0[ours])
        n = acc["clear_returns"]
        share_theirs, share_ours = acc["theirs"] / n, acc["ours"] / n
        rt, ro = np.concatenate(ranges_theirs), np.concatenate(ranges_ours)
        pct = lambda r: np.percentile(r, [5, 50, 95]).round(3).tolist() if len(r) else None  # noqa: E731
        rows.append(
            {
                "visibility_m": v,
                "clear_returns": n,
                "share_theirs": share_theirs,
                "share_ours": share_ours,
                "relative_difference": (share_ours - share_theirs) / share_theirs if share_theirs else None,
                "fogged_beams_clear_range_m_5_50_95": {"theirs": pct(rt), "ours": pct(ro)},
                # Their fog returns' intensities; below 0.5 they round to 0 by their own rule for hard returns.
                "theirs_fog_intensity_0_255_5_50_95": pct(np.concatenate(fog_intensity)),
                "theirs_share_with_fog_intensity_at_least_half": float(
                    (np.concatenate(fog_intensity) >= 0.5).sum() / n
                ),
                "ours_fog_returns_on_beams_without_clear_return": acc["ours_from_no_return"],
                "ours_lost_share": acc["ours_lost"] / n,
            }
        )
    out = {"scene": args.scene, "rig": args.rig, "seeds": args.seeds, "rounded": args.rounded, "fog": rows}
    print(json.dumps(out, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
