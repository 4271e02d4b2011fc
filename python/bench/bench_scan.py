"""Benchmark: one `os1-128-roof` frame scanned from Python vs the same scan through the Rust API.

    python python/bench/bench_scan.py [--scene city] [--rig os1-128-roof] [--repeats 15]

Rust API: `Scenario::bundled(scene).rig(rig).scan()` timed inside the extension with no Python
object involved (`groundtruth._native._time_rust_scan`). Python: `groundtruth.scan(scene, rig)`
(argument checks, the same scenario scan with the GIL released, Frame objects), then the same plus
reading `xyz`, `label` and `ground` as numpy arrays and `points()`. The builds are the same, so
the difference is the binding's cost. Prints one JSON object; min and median over the repeats.
"""

import argparse
import json
import statistics
import time

import groundtruth as gt
from groundtruth import _native


def timed(fn, repeats):
    out = []
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        out.append(time.perf_counter() - t)
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--scene", default="city")
    ap.add_argument("--rig", default="os1-128-roof")
    ap.add_argument("--repeats", type=int, default=15)
    a = ap.parse_args()

    def py_scan():
        return gt.scan(a.scene, a.rig)

    def py_scan_arrays():
        (f,) = gt.scan(a.scene, a.rig)
        f.xyz, f.label, f.ground, f.points()

    py_scan()  # warm-up: page cache, allocator
    # Interleaved, so that load from other processes hits both sides alike.
    rust, py, py_arrays = [], [], []
    for _ in range(a.repeats):
        rust += _native._time_rust_scan(a.scene, a.rig, 1)
        py += timed(py_scan, 1)
        py_arrays += timed(py_scan_arrays, 1)
    (f,) = py_scan()

    def stats(v):
        return {"min_ms": round(1e3 * min(v), 2), "median_ms": round(1e3 * statistics.median(v), 2)}

    r, p, pa = stats(rust), stats(py), stats(py_arrays)
    print(
        json.dumps(
            {
                "scene": a.scene,
                "rig": a.rig,
                "cells": f.shape[0] * f.shape[1],
                "returns": f.returns,
                "repeats": a.repeats,
                "rust_api_scan": r,
                "python_scan": p,
                "python_scan_plus_arrays": pa,
                "python_over_rust_min": round(p["min_ms"] / r["min_ms"] - 1.0, 4),
                "python_over_rust_median": round(p["median_ms"] / r["median_ms"] - 1.0, 4),
                "with_arrays_over_rust_median": round(pa["median_ms"] / r["median_ms"] - 1.0, 4),
            },
            indent=1,
        )
    )


if __name__ == "__main__":
    main()
