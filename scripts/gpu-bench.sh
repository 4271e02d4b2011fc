#!/usr/bin/env bash
# The GPU figures of docs/scanning.md in one JSON document, for anyone with a GPU (issue 38):
# the adapter; `bench raycast` end to end and the kernel alone, `--backend gpu` (with the CWBVH and
# the BVH2 layout, `GROUNDTRUTH_GPU_BVH`) against the same host's all-core `bvh`, on fixture-terrain (1.3 M triangles, 128 x 2048 rays), city with
# os1-128-roof and forest-dense with hdl64e-roof; `scan` of 100 moving os1-128-roof city frames and
# `dataset` of 1,000 hdl64e-roof city frames, wall time for both backends; and the agreement
# contract (`bench agreement`) on city and forest-dense, with and without measurement effects.
# Under 5 minutes on a GPU machine (lavapipe takes far longer: use FRAMES_SCALE=0.05 there).
#
#   scripts/gpu-bench.sh > gpu-bench.json           # WGPU_ADAPTER_NAME=... to pick an adapter
set -euo pipefail
cd "$(dirname "$0")/.."
BIN=${GROUNDTRUTH:-target/dist/groundtruth}
[ -x "$BIN" ] || cargo build --profile dist --features full --bin groundtruth >&2
scale=${FRAMES_SCALE:-1}
n() { python3 -c "import sys; print(max(1, round($1 * $scale)))"; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
log() { echo "[gpu-bench] $*" >&2; }

# Seconds of wall time of a command (its output discarded).
wall() { local t0 t1; t0=$(date +%s.%N); "$@" >/dev/null; t1=$(date +%s.%N); python3 -c "print(round($t1 - $t0, 3))"; }

raycast() { # scene rig frames backend (the GPU's BVH layout from $layout)
  if [ "$4" = gpu ]; then
    GROUNDTRUTH_GPU_BVH=$layout "$BIN" bench raycast --scene "$1" --rig "$2" --frames "$3" --backend gpu
  else
    "$BIN" bench raycast --scene "$1" --rig "$2" --frames "$3" --backend "$4"
  fi
}

out="$work/out.json"
echo "{" > "$out"
echo "\"adapter\": $("$BIN" list | python3 -c 'import json,sys; l=[x for x in sys.stdin if x.strip().startswith("gpu")]; print(json.dumps(l[0].split(":",1)[1].strip() if l else None))')," >> "$out"
echo "\"host_cores\": $(nproc)," >> "$out"

echo "\"raycast\": [" >> "$out"
first=1
for spec in "fixture-terrain fixture-128x2048 $(n 400)" "city os1-128-roof $(n 200)" "forest-dense hdl64e-roof $(n 200)"; do
  set -- $spec
  # The GPU with each BVH layout (the default first), then the CPU.
  for run in gpu:cwbvh gpu:bvh2 bvh:-; do
    backend=${run%%:*} layout=${run#*:}
    log "bench raycast $1 $2 $3 frames, $backend $layout"
    [ $first = 1 ] || echo "," >> "$out"
    first=0
    if [ "$layout" = - ]; then
      raycast "$1" "$2" "$3" "$backend" >> "$out"
    else
      raycast "$1" "$2" "$3" "$backend" | python3 -c "import json,sys; d=json.load(sys.stdin); d['gpu_bvh']='$layout'; print(json.dumps(d))" >> "$out"
    fi
  done
done
echo "]," >> "$out"

log "scan: $(n 100) moving os1-128-roof city frames, kitti"
scan_gpu=$(wall "$BIN" scan --scene city --rig os1-128-roof --frames "$(n 100)" --speed-m-per-s 10 --format kitti --backend gpu --out "$work/scan-gpu")
scan_bvh=$(wall "$BIN" scan --scene city --rig os1-128-roof --frames "$(n 100)" --speed-m-per-s 10 --format kitti --backend bvh --out "$work/scan-bvh")
echo "\"scan_s\": {\"frames\": $(n 100), \"gpu\": $scan_gpu, \"bvh\": $scan_bvh}," >> "$out"

frames=$(n 100)
{
  for id in $(seq 0 9); do
    printf '[[sequences]]\nid = %d\nscene = "city"\nseed = %d\nrig = "hdl64e-roof"\nframes = %d\nspeed_m_per_s = 10.0\n\n' "$id" "$((id + 1))" "$frames"
  done
} > "$work/dataset.toml"
log "dataset: 10 x $frames hdl64e-roof city frames"
ds_gpu=$(wall "$BIN" dataset --config "$work/dataset.toml" --out "$work/ds-gpu" --backend gpu)
ds_bvh=$(wall "$BIN" dataset --config "$work/dataset.toml" --out "$work/ds-bvh" --backend bvh)
echo "\"dataset_s\": {\"frames\": $((10 * frames)), \"gpu\": $ds_gpu, \"bvh\": $ds_bvh}," >> "$out"

echo "\"agreement\": [" >> "$out"
first=1
for spec in "city hdl64e-roof" "forest-dense hdl64e-roof"; do
  set -- $spec
  for ideal in "" "--ideal"; do
    log "bench agreement $1 $2 $ideal"
    [ $first = 1 ] || echo "," >> "$out"
    first=0
    # A broken contract prints its JSON and exits non-zero: keep the JSON, go on.
    "$BIN" bench agreement --scene "$1" --rig "$2" --frames "$(n 5)" $ideal >> "$out" || true
  done
done
echo "]" >> "$out"
echo "}" >> "$out"
python3 - "$out" <<'PY'
import json, sys
doc = json.load(open(sys.argv[1]))
def pair(scene):
    # Each scene's runs in the order the script ran them: gpu with cwbvh, gpu with bvh2, bvh.
    cw, b2, bvh = [r for r in doc["raycast"] if r["geometry"].startswith(scene)][:3]
    kernel = lambda r: (r.get("device") or {}).get("kernel_rays_per_s")
    return {
        "gpu_rays_per_s": cw["rays_per_s"],
        "gpu_kernel_rays_per_s": kernel(cw),
        "gpu_bvh2_rays_per_s": b2["rays_per_s"],
        "gpu_bvh2_kernel_rays_per_s": kernel(b2),
        "bvh_rays_per_s": bvh["rays_per_s"],
        "gpu_over_bvh": cw["rays_per_s"] / bvh["rays_per_s"],
    }
doc["summary"] = {
    "raycast": {s: pair(s) for s in ["fixture-terrain", "city", "forest-dense"]},
    "scan_bvh_over_gpu": doc["scan_s"]["bvh"] / doc["scan_s"]["gpu"],
    "dataset_bvh_over_gpu": doc["dataset_s"]["bvh"] / doc["dataset_s"]["gpu"],
    "contract_holds": all(a["contract"]["holds"] for a in doc["agreement"]),
}
print(json.dumps(doc, indent=2))
PY
