"""Patchwork++ scored on a labelled SemanticKITTI-layout recording under the protocol of
`groundtruth eval --dataset` (`semantickitti`: ground = 40 road, 44 parking, 48 sidewalk,
49 other-ground, 60 lane-marking, 72 terrain; 0 and 1 left out; points at 0, 0, 0 left out and not
given to Patchwork++), so that both are compared on the same frames and counts:

    python python/bench/eval_patchwork.py DATASET_DIR [--sensor-height 1.73] [--protocol patchworkpp]
                                          [--ground 40,44,48,49,60,72,111] [--ignore 110]

`--protocol patchworkpp` also leaves vegetation (70) out, as Patchwork++'s own evaluation does;
`--ground` and `--ignore` change the ground set and leave more classes out, as `groundtruth eval
dataset`'s flags of the same names do (WADS's snowfall: `--ground 40,44,48,49,60,72,111 --ignore 110`).
One estimator runs over each sequence's frames in order (as its ROS node would). Prints one JSON
object: pooled precision, recall, F1 and counts, the frame mean of F1, the worst frame, and the
milliseconds per frame.
"""

import argparse
import contextlib
import importlib.metadata
import json
import os
import pathlib
import sys
import time

import numpy as np
import pypatchworkpp

GROUND = np.array([40, 44, 48, 49, 60, 72], dtype=np.uint32)


def sequences(root):
    root = pathlib.Path(root)
    if (root / "velodyne").is_dir():
        return [root]
    return sorted(p for p in (root / "sequences").iterdir() if (p / "velodyne").is_dir())


@contextlib.contextmanager
def quiet_stdout():
    """Patchwork++'s C++ code prints to the process's standard output: sent to /dev/null here, so
    that standard output holds the JSON alone."""
    sys.stdout.flush()
    saved = os.dup(1)
    with open(os.devnull, "w") as null:
        os.dup2(null.fileno(), 1)
        try:
            yield
        finally:
            os.dup2(saved, 1)
            os.close(saved)


def f1(tp, fp, fn):
    d = 2 * tp + fp + fn
    return 2 * tp / d if d else float("nan")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dataset")
    ap.add_argument("--sensor-height", type=float, default=1.73)
    ap.add_argument("--protocol", choices=["semantickitti", "patchworkpp"], default="semantickitti")
    ap.add_argument("--ground", help="ground class ids replacing the protocol's, comma-separated")
    ap.add_argument("--ignore", help="class ids left out beside the protocol's, comma-separated")
    args = ap.parse_args()
    ignored = [0, 1] + ([70] if args.protocol == "patchworkpp" else [])
    def class_ids(flag, text):
        try:
            ids = [int(x) for x in text.split(",")]
        except ValueError:
            sys.exit(f"{flag}: `{text}` is not a comma-separated list of class ids (e.g. 40,44,48)")
        if any(not 0 <= i <= 0xFFFF for i in ids):
            sys.exit(f"{flag}: class ids are 0 ..= 65535")
        return ids

    ground = GROUND
    if args.ground is not None:
        ground = np.array(class_ids("--ground", args.ground), dtype=np.uint32)
    if args.ignore is not None:
        ignored += class_ids("--ignore", args.ignore)
    if np.isin(ground, ignored).any():
        sys.exit("--ground and --ignore share a class")
    tot = {"tp": 0, "fp": 0, "fn": 0, "tn": 0}
    frames, times = [], []
    for seq in sequences(args.dataset):
        params = pypatchworkpp.Parameters()
        params.sensor_height = args.sensor_height
        with quiet_stdout():
            pw = pypatchworkpp.patchworkpp(params)
        for binf in sorted((seq / "velodyne").glob("*.bin")):
            pts = np.fromfile(binf, dtype=np.float32).reshape(-1, 4)
            labels = np.fromfile(seq / "labels" / (binf.stem + ".label"), dtype=np.uint32) & 0xFFFF
            if len(labels) != len(pts):
                sys.exit(f"{binf}: {len(labels)} labels for {len(pts)} points")
            returns = ~np.all(pts[:, :3] == 0, axis=1)
            idx = np.flatnonzero(returns)
            t = time.perf_counter()
            with quiet_stdout():
                pw.estimateGround(pts[idx])
            times.append((time.perf_counter() - t) * 1e3)
            pred = np.zeros(len(pts), bool)
            pred[idx[np.asarray(pw.getGroundIndices(), dtype=np.int64)]] = True
            scored = returns & ~np.isin(labels, ignored)
            truth = np.isin(labels, ground)
            c = {
                "tp": int((truth & pred & scored).sum()),
                "fp": int((~truth & pred & scored).sum()),
                "fn": int((truth & ~pred & scored).sum()),
                "tn": int((~truth & ~pred & scored).sum()),
            }
            for k in tot:
                tot[k] += c[k]
            frames.append({"sequence": seq.name, "frame": binf.stem, "f1": f1(c["tp"], c["fp"], c["fn"]), **c})
    worst = min(frames, key=lambda f: f["f1"])
    print(
        json.dumps(
            {
                "method": "patchwork++ (pypatchworkpp %s)" % importlib.metadata.version("pypatchworkpp"),
                "protocol": args.protocol,
                "ground": [int(g) for g in ground],
                "ignored": sorted(set(ignored)),
                "sensor_height_m": args.sensor_height,
                "pooled": {
                    "precision": tot["tp"] / max(1, tot["tp"] + tot["fp"]),
                    "recall": tot["tp"] / max(1, tot["tp"] + tot["fn"]),
                    "f1": f1(tot["tp"], tot["fp"], tot["fn"]),
                    **tot,
                },
                "frame_mean_f1": float(np.mean([f["f1"] for f in frames])),
                "worst_frame": {"sequence": worst["sequence"], "frame": worst["frame"], "f1": worst["f1"]},
                "mean_ms": float(np.mean(times)),
                "frames": frames,
            },
            indent=1,
        )
    )


if __name__ == "__main__":
    main()
