"""Benchmark: Patchwork++ on the same KITTI `.bin` files that `groundtruth bench classify --input` times.

    taskset -c 0 python python/bench/bench_patchwork.py FILE_OR_DIR ... [--repeats 20]

Each frame is read with `np.fromfile` and segmented by `pypatchworkpp` (default parameters) per
repeat, so the figure covers read + segmentation as `bench classify --input` covers read + order +
classify. Run both on the same core in one session: this machine's timings drift between minutes.
Prints one JSON object: per file the min and median milliseconds and the ground count.
"""

import argparse
import json
import os
import pathlib
import statistics
import sys
import time

import numpy as np
import pypatchworkpp


def frames(paths):
    out = []
    for p in map(pathlib.Path, paths):
        if p.is_dir():
            out.extend(sorted(p.glob("*.bin")))
        elif p.suffix == ".bin" and p.is_file():
            out.append(p)
        else:
            sys.exit(f"error: `{p}` is neither an existing .bin file nor a directory")
    if not out:
        sys.exit("error: no .bin files given")
    return out


def quiet(fn):
    """Calls `fn` with the process's stdout sent to stderr: the C++ constructor prints a line to
    stdout even with `verbose = False`, which would break the JSON."""
    sys.stdout.flush()
    saved = os.dup(1)
    os.dup2(2, 1)
    try:
        return fn()
    finally:
        os.dup2(saved, 1)
        os.close(saved)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("inputs", nargs="+")
    ap.add_argument("--repeats", type=int, default=20)
    a = ap.parse_args()
    if a.repeats < 1:
        sys.exit("error: --repeats must be at least 1")
    files = frames(a.inputs)
    params = pypatchworkpp.Parameters()
    params.verbose = False
    pw = quiet(lambda: pypatchworkpp.patchworkpp(params))
    per_file = []
    for f in files:
        if f.stat().st_size % 16:
            sys.exit(f"error: `{f}` is not a KITTI .bin (size not a multiple of 16 bytes)")
        times, ground = [], 0
        for _ in range(a.repeats):
            t = time.perf_counter()
            xyzi = np.fromfile(f, dtype=np.float32).reshape(-1, 4)
            pw.estimateGround(xyzi)
            ground = len(pw.getGround())
            times.append((time.perf_counter() - t) * 1e3)
        per_file.append(
            {
                "file": str(f),
                "points": int(len(xyzi)),
                "ground": ground,
                "total_ms": {"min": min(times), "median": statistics.median(times)},
            }
        )
    print(json.dumps({"method": "patchwork++", "repeats": a.repeats, "per_file": per_file}, indent=2))


if __name__ == "__main__":
    main()
