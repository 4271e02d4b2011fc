#!/usr/bin/env python3
"""Our rain side by side with a real spinning lidar's rain detections (per sky beam, per rate).

    python rain_vs_measured.py [--bin target/quick/groundtruth] [--rig vlp16-roof] [--scene rural]
                               [--seeds 0 1] [--frames 5] [--rates 5 10 20 50]

The measurement (docs/weather.md, "Rain: the measurement it is calibrated against"): Linnhoff,
Hofrichter, Elster, Rosenberger and Winner 2022, "Measuring the influence of environmental
conditions on automotive lidar sensors", Sensors 22(14) 5266 (a stationary long-term experiment
in natural rain, a disdrometer for the rate), read from the authors' model calibrated on it
(github.com/openMSL/sl-1-2-reflection-based-lidar-object-model, ``profile_VLP16.hpp.in``): a
**Velodyne VLP-16** beam returns a detection from rain with probability ``1.69e-4`` per mm/h
(linear in the rate), its range log-normal with ``ln R`` mean 1.362 and sd 0.784 (median 3.9 m,
51 % nearer than 4 m).

Runs the built ``groundtruth`` binary (``scan --format pcd``, our organized PCD: one cell per
beam) standing still (``--speed-m-per-s 0``, as the measurement did), once without rain
(``clear``: the sensor's threshold, no medium) and once in rain of each rate, same seed and
frames, so that cell ``k`` is the same beam in both. A **sky beam** is a cell without a return in
the clear scan (no detectable surface); the figure compared is the share of sky beams whose cell
holds a drop (label 151) in the rain scan. Also reported: drops on beams with a surface (a drop
outshining the target), the drops' median range and their share nearer than 2 and 4 m, and the
share per upward layer (the measurement's per-layer factors: 0.49, 0.64, 0.58, 0.57, 1.85, 1.5,
1.5, 0.88 for +1 .. +15 deg).

Prints one JSON object; ``ratio`` is ours over the measured figure (the target: within a factor
2, i.e. 0.5 ..= 2, at the calibrated rates 10 and 50 mm/h).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import tempfile
from pathlib import Path

import numpy as np

from particles_vs_measured import RAIN, scan

# Linnhoff et al. 2022 (VLP-16), through the authors' calibrated model: rain detections per beam
# per mm/h, and the log-normal of their ranges (ln metres).
MEASURED_PER_BEAM_PER_MM_H = 1.69e-4
MEASURED_LN_RANGE_MEAN, MEASURED_LN_RANGE_SD = 1.362, 0.784


def lognormal_below(r_m: float) -> float:
    """The measured share of rain detections nearer than ``r_m``."""
    z = (math.log(r_m) - MEASURED_LN_RANGE_MEAN) / MEASURED_LN_RANGE_SD
    return 0.5 * (1.0 + math.erf(z / math.sqrt(2.0)))


def compare(clear: np.ndarray, rain: np.ndarray, rate: float) -> dict:
    """Our drops per sky beam against the measured figure at ``rate`` mm/h."""
    assert len(clear) == len(rain), "the two scans must have the same cells"
    sky = ~np.isfinite(clear["x"])
    drop = rain["label"] == RAIN
    r = rain["range"][drop]
    measured = MEASURED_PER_BEAM_PER_MM_H * rate
    ours = float((drop & sky).sum()) / max(int(sky.sum()), 1)
    rings = sorted(set(int(x) for x in rain["ring"][sky]))
    return {
        "beams": int(len(rain)),
        "sky_beams": int(sky.sum()),
        "drops_on_sky_beams": int((drop & sky).sum()),
        "drops_on_surface_beams": int((drop & ~sky).sum()),
        "per_sky_beam_percent": round(100.0 * ours, 4),
        "measured_percent": round(100.0 * measured, 4),
        "ratio": round(ours / measured, 2),
        "median_m": round(float(np.median(r)), 2) if len(r) else None,
        "below_2m_percent": round(100.0 * float((r < 2).mean()), 1) if len(r) else None,
        "below_4m_percent": round(100.0 * float((r < 4).mean()), 1) if len(r) else None,
        "per_ring_percent": {
            ring: round(100.0 * float((drop & sky & (rain["ring"] == ring)).sum())
                        / max(int((sky & (rain["ring"] == ring)).sum()), 1), 3)
            for ring in rings
        },
    }


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default="target/quick/groundtruth")
    ap.add_argument("--scene", default="rural")
    ap.add_argument("--rig", default="vlp16-roof")
    ap.add_argument("--seeds", type=int, nargs="+", default=[0, 1])
    ap.add_argument("--frames", type=int, default=5)
    ap.add_argument("--rates", type=float, nargs="+", default=[5.0, 10.0, 20.0, 50.0])
    args = ap.parse_args()
    result = {
        "scene": args.scene, "rig": args.rig, "seeds": args.seeds, "frames": args.frames,
        "measured_median_m": round(math.exp(MEASURED_LN_RANGE_MEAN), 2),
        "measured_below_2m_percent": round(100.0 * lognormal_below(2.0), 1),
        "measured_below_4m_percent": round(100.0 * lognormal_below(4.0), 1),
    }
    with tempfile.TemporaryDirectory() as tmp:
        def cells(weather: str, seed: int) -> np.ndarray:
            out = Path(tmp) / f"{weather}-{seed}"
            return scan(args.bin, args.scene, args.rig, weather, seed, args.frames, out, 0.0, cells=True)

        clear = np.concatenate([cells("clear", s) for s in args.seeds])
        for rate in args.rates:
            spec = f"rain:rate_mm_h={rate:g}"
            rain = np.concatenate([cells(spec, s) for s in args.seeds])
            result[spec] = compare(clear, rain, rate)
    json.dump(result, sys.stdout, indent=1)
    print()
    return 0


if __name__ == "__main__":
    sys.exit(main())
