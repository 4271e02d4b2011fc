#!/usr/bin/env bash
# The Python package's CI: a venv with maturin, numpy, pytest, pypatchworkpp, mypy and the ROS 2 bag
# clients (mcap + mcap-ros2-support, rosbags, rerun-sdk) from PyPI, the
# `groundtruth` package installed from python/ (the README's `pip install` line, release build),
# then mypy's stubtest (the .pyi stubs against the built module) and pytest on python/tests (the
# package's tests, including round trips against the command-line program's files) and
# examples/python (the Patchwork++ scenario suite a user would copy).
#
#   scripts/python-ci.sh            # venv in $GT_PY_VENV (default target/python-venv)
#
# Builds in the workspace's target dir (CARGO_TARGET_DIR, default ./target), so a preceding
# `cargo build --release` has built every Rust dependency already. Needs python3 (3.9+) with venv.
set -euo pipefail
cd "$(dirname "$0")/.."
start=$(date +%s)
log() { echo "[python-ci $(( $(date +%s) - start ))s] $*"; }
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$PWD/target}"
venv="${GT_PY_VENV:-$CARGO_TARGET_DIR/python-venv}"

if [ ! -x "$venv/bin/python" ]; then
  log "venv $venv"
  if ! python3 -m venv "$venv" 2>/dev/null; then
    # Debian's python3 ships venv separately.
    rm -rf "$venv"
    apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq python3-venv >/dev/null
    python3 -m venv "$venv"
  fi
fi
py="$venv/bin/python"
export PATH="$venv/bin:$PATH"  # the maturin build backend runs the `maturin` program
log "pip install maturin numpy pytest pypatchworkpp mypy, and the ROS 2 bag clients (mcap, rosbags, rerun)"
"$py" -m pip install -q --upgrade pip
"$py" -m pip install -q "maturin>=1.9,<2" numpy pytest "pypatchworkpp==1.4.1" mypy \
  "mcap==1.6.0" "mcap-ros2-support==0.6.0" "rosbags==0.11.9" "rerun-sdk==0.41.0"

# GROUNDTRUTH_BIN: the CLI of the round-trip tests (CI passes the test build's
# target/debug/groundtruth); default: the release build.
if [ -z "${GROUNDTRUTH_BIN:-}" ]; then
  log "cargo build --release --bin groundtruth (the CLI of the round-trip tests)"
  cargo build --release --locked --bin groundtruth
  GROUNDTRUTH_BIN="$CARGO_TARGET_DIR/release/groundtruth"
fi

# GT_PY_PROFILE: the cargo profile of the extension (default release, as the README's `pip install`
# builds it). CI passes `dev`: the test build's dependencies are reused instead of optimised again.
profile="${GT_PY_PROFILE:-release}"
log "pip install ./python (maturin, $profile profile)"
MATURIN_PEP517_ARGS="--profile $profile" \
  "$py" -m pip install -q --no-build-isolation --force-reinstall --no-deps ./python

log "mypy.stubtest: the type stubs match the module"
(cd "$CARGO_TARGET_DIR" && "$py" -m mypy.stubtest groundtruth._native)

log "pytest python/tests examples/python"
export GROUNDTRUTH_BIN GT_REQUIRE_CLI=1
# From outside the source tree, so the installed package (not python/groundtruth/) is imported.
(cd "$CARGO_TARGET_DIR" && "$py" -m pytest -q -p no:cacheprovider "$OLDPWD/python/tests" "$OLDPWD/examples/python")
log "done"
