#!/usr/bin/env bash
# Speed and memory of `groundtruth sweep` (issue 12's targets): 1,000 configurations of
# `lux-roof-4` on `city` (scan, nitsch, metrics), and peak RSS over N configurations.
#
#   scripts/sweep-bench.sh [N ...]        # default: 1000 10000
#
# Prints each run's JSON summary (configurations_per_s, prepare_s, seconds) and the wall time,
# CPU time and peak RSS that /usr/bin/time -v measures (apt-get install -y time if missing).
set -euo pipefail
cd "$(dirname "$0")/.."
BIN=${GROUNDTRUTH:-target/release/groundtruth}
[ -x "$BIN" ] || cargo build --release
counts=("$@")
[ ${#counts[@]} -gt 0 ] || counts=(1000 10000)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for n in "${counts[@]}"; do
  # 10 heights x 10 pitches x (n / 100) yaws, one seed: n configurations.
  yaws=$(( n / 100 ))
  [ "$yaws" -ge 1 ] || { echo "N must be a multiple of 100" >&2; exit 2; }
  cat > "$work/bench-$n.toml" <<TOML
scenes = ["city"]
rigs = ["lux-roof-4"]
seeds = [0]
methods = ["nitsch"]
[mount]
z_m = { from = 1.2, to = 2.1, step = 0.1 }
pitch_deg = { from = -5, to = 4, step = 1 }
yaw_deg = { from = 0, to = $(( yaws - 1 )), step = 1 }
TOML
  echo "== $n configurations"
  /usr/bin/time -v "$BIN" sweep --config "$work/bench-$n.toml" --out "$work/out-$n" 2> "$work/time-$n.txt"
  grep -E 'Elapsed \(wall|User time|System time|Maximum resident' "$work/time-$n.txt"
  echo "rows: $(( $(wc -l < "$work/out-$n/results.csv") - 1 ))"
done
