#!/usr/bin/env python3
"""Flakes per return mode: our snowfall seen by one roof sensor in its strongest, last and dual
return modes (docs/weather.md, "Return modes").

    python snow_return_modes.py [--bin target/debug/groundtruth] [--model pandar64 | all]
                                [--modes strongest last dual] [--snow 1 3] [--scene rural]
                                [--seeds 0 1] [--frames 2]

Writes a one-sensor rig file per mode (the catalogued ``--model`` at x 1.3, z 1.85 with
``return_mode``, as the ``*-roof`` presets mount it), runs ``groundtruth scan --format pcd`` on the
scene moving at 10 m/s in snow of each rate, and reads our organized PCDs (every echo plane) with
the standard library only. Per mode and rate it prints:

* ``share``: flakes (label 152) among all returns of every plane. A dual-mode shot fills its
  second plane only with a second, different echo, so this is the share of *unique* returns, the
  figure WADS's dual-return recordings give (4.7-8.4 %, issue 45);
* ``median_m``: the flakes' median range;
* ``shots``: shots with at least one flake among shots with a return;
* ``behind``: flakes in plane 0 with a surface (not a flake) in plane 1 of the same shot, as a
  share of the flakes (dual only).

The built-in models without return modes (``vlp16``, ``hdl64e``, ``os1-64``, ``os1-128``) are
scanned as they are (``single``: strongest) and with ``max_echoes = 2`` (``two echoes``), which the
weather meets as dual (every echo, nearest first). ``--model all`` runs every roof sensor in turn.
"""

from __future__ import annotations

import argparse
import statistics
import struct
import subprocess
import sys
import tempfile
from pathlib import Path

SNOW = 152
# Our organized PCD's record (sim/src/io/pcd/writer.rs), packed little-endian: x y z intensity
# ring time label instance ground range sensor echo column nx ny nz.
RECORD = struct.Struct("<ffffHdIIBfBBIfff")
LABEL, RANGE = 6, 9

# The models without catalogued return modes: one echo as they are, two with max_echoes = 2.
BUILT_IN = ("vlp16", "hdl64e", "os1-64", "os1-128")
# Every sensor of the `*-roof` presets (sim/src/rig/presets.rs).
ROOF_MODELS = (
    "vlp16", "hdl64e", "os1-64", "os1-128", "hdl32e", "vlp32c", "vls128", "os0-128", "os2-128", "pandar64",
    "pandar-xt32", "rs-helios-5515",
)

RIG = """name = "{name}"

[[sensors]]
name = "roof"
mount = {{ x_m = 1.3, y_m = 0.0, z_m = 1.85, roll_deg = 0.0, pitch_deg = 0.0, yaw_deg = 0.0 }}

[sensors.spec]
model = "{model}"
{setting}
"""


def read_pcd(path: Path) -> tuple[int, int, int, list[tuple]]:
    """Width, rows, planes and every cell of one organized PCD of ours (NaN x: no return)."""
    head, body = path.read_bytes().split(b"DATA binary\n", 1)
    lines = head.decode().splitlines()
    fields = {line.split()[0]: line.split()[1:] for line in lines if line and not line.startswith("#")}
    planes = int(next(line for line in lines if "planes=" in line).split("planes=")[1].split()[0])
    width, height = int(fields["WIDTH"][0]), int(fields["HEIGHT"][0])
    return width, height // planes, planes, list(RECORD.iter_unpack(body))


def count(paths: list[Path]) -> dict:
    """The flakes' share of the returns, their median range and where they sit in the shots."""
    returns = flakes = behind = shots = flake_shots = 0
    ranges: list[float] = []
    for path in paths:
        width, rows, planes, cells = read_pcd(path)
        for row in range(rows):
            for col in range(width):
                shot = [cells[(k * rows + row) * width + col] for k in range(planes)]
                hit = [c for c in shot if c[0] == c[0]]
                if not hit:
                    continue
                shots += 1
                returns += len(hit)
                snow = [c for c in hit if c[LABEL] == SNOW]
                flakes += len(snow)
                ranges += [c[RANGE] for c in snow]
                flake_shots += bool(snow)
                first, second = shot[0], shot[1] if planes > 1 else None
                if first[0] == first[0] and first[LABEL] == SNOW and second and second[0] == second[0]:
                    behind += second[LABEL] != SNOW
    return {
        "returns": returns,
        "share": round(100.0 * flakes / max(returns, 1), 2),
        "median_m": round(statistics.median(ranges), 2) if ranges else None,
        "shots": round(100.0 * flake_shots / max(shots, 1), 2),
        "behind": round(100.0 * behind / max(flakes, 1), 1),
    }


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", default="target/debug/groundtruth")
    ap.add_argument("--model", default="pandar64")
    ap.add_argument("--modes", nargs="+", default=["strongest", "last", "dual"])
    ap.add_argument("--scene", default="rural")
    ap.add_argument("--seeds", type=int, nargs="+", default=[0, 1])
    ap.add_argument("--frames", type=int, default=2)
    ap.add_argument("--snow", type=float, nargs="+", default=[1.0, 3.0])
    args = ap.parse_args()
    for model in ROOF_MODELS if args.model == "all" else [args.model]:
        run(args, model)
    return 0


def run(args: argparse.Namespace, model: str) -> None:
    """Every mode and rate of one model."""
    if model in BUILT_IN:
        settings = {"single": "", "two echoes": "measurement = { max_echoes = 2 }"}
    else:
        settings = {mode: f'return_mode = "{mode}"' for mode in args.modes}
    with tempfile.TemporaryDirectory() as tmp:
        for rate in args.snow:
            for mode, setting in settings.items():
                rig = Path(tmp) / f"{model}-{mode.replace(' ', '-')}.toml"
                rig.write_text(RIG.format(name=rig.stem, model=model, setting=setting))
                pcds = []
                for seed in args.seeds:
                    out = Path(tmp) / f"{rig.stem}-{rate:g}-{seed}"
                    cmd = [
                        args.bin, "scan", "--scene", args.scene, "--rig", str(rig), "--seed", str(seed),
                        "--frames", str(args.frames), "--speed-m-per-s", "10", "--weather",
                        f"snow:rate_mm_h={rate:g}", "--format", "pcd", "--out", str(out),
                    ]
                    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
                    pcds += sorted(out.glob("*.pcd"))
                print(f"{model} {mode} snow {rate:g} mm/h: {count(pcds)}", flush=True)


if __name__ == "__main__":
    sys.exit(main())
