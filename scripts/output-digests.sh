#!/usr/bin/env bash
# Digests of what the program makes: the README's commands, the bundled dataset and sweep
# examples, and `classify` / `eval` on the files they write. Used to show that a refactor leaves
# every byte the same: run it with the old and the new binary and `diff` the two listings.
#
#   scripts/output-digests.sh BINARY WORKDIR > digests.txt
#
# Manifests are listed without their `spec` and `generator` fields (a manifest records how it was
# asked for; the clouds, decisions and scores must not move). JSON reports are listed without
# timing fields (`*_ms`, `*_s` wall times, `seconds`); a sweep's result rows as a set (they are
# appended in the order configurations finish). Pictures are listed as they are.
set -euo pipefail
bin=$(realpath "$1")
work=$2
repo=$(cd "$(dirname "$0")/.." && pwd)
rm -rf "$work"
mkdir -p "$work"
cd "$work"

run() { "$bin" "$@" > /dev/null; }

# The README's commands (demo; ground truth on demand; weather; bags; classify; eval).
run demo --out demo
run scan --scene basin --rig lux-roof-4 --out basin --frames 5 --speed 10 --seed 7
run scan --scene city --rig os1-128-roof --out city --format pcd,ply,kitti,las --ideal
run render --scene ramp-up --out ramp.png
run scan --scene city --rig hdl64e-roof --weather fog:visibility_m=50 --out fog
run scan --scene rural --rig vlp16-roof --weather snow:rate_mm_h=2 --speed 10 --frames 2 --out snow
run scan --scene hill --rig vlp16-roof --frames 3 --speed 8 --yaw-rate 0.2 --out turn
run scan --scene city --rig os1-64-roof --frames 5 --speed 10 --format mcap --pcd-layout ouster --out bagscan
run classify --method learned --input bagscan/bag --topic /roof/points --out c-bag
run classify --method learned --input city/frame_000000.bin --out c-kitti
run classify --method nitsch --input city/frame_000000.bin --rig os1-128-roof --out c-kitti-rig
run scan --scene city --rig os1-64-roof --format pcd --pcd-layout ouster --out ouster
run classify --method nitsch --input ouster/frame_000000.pcd --rig os1-64-roof --out c-ouster
run classify --method grid --input basin --out c-grid
run eval --scene city --rig lux-roof-4 --frames 2 --json eval-city.json
# The bundled dataset, and eval --dataset on it.
run dataset --config "$repo/examples/dataset-semantickitti.toml" --out dataset
run eval --dataset dataset --methods nitsch,learned,grid --json eval-dataset.json
# The bundled sweep.
run sweep --config "$repo/examples/sweep-mount.toml" --out sweep

python3 - <<'PY'
import hashlib, json, os, re
timing = re.compile(r"(_ms|_s|seconds|_per_s|elapsed.*|generator|spec|threads)$")
def strip(v):
    if isinstance(v, dict):
        return {k: strip(x) for k, x in v.items() if not timing.search(k) or k in ("speed_m_per_s", "yaw_rate_rad_per_s", "yaw_rate_deg_per_s", "start_time_s", "frame_period_s")}
    if isinstance(v, list):
        return [strip(x) for x in v]
    return v
for root, dirs, files in sorted(os.walk(".")):
    dirs.sort()
    for f in sorted(files):
        p = os.path.join(root, f)
        data = open(p, "rb").read()
        if f.startswith("results."):
            # Rows are appended as configurations finish (a resumable log): compare them as a set.
            data = b"".join(sorted(data.splitlines(keepends=True)))
        elif f.endswith(".json"):
            data = json.dumps(strip(json.loads(data)), sort_keys=True).encode()
        print(hashlib.sha256(data).hexdigest()[:16], p)
PY
