"""Shared fixtures: scans are cached per session (they are deterministic) and the command-line
program is found for the round trips."""

import os
import pathlib
import shutil
import subprocess

import pytest

import groundtruth as gt

REPO = pathlib.Path(__file__).resolve().parents[2]


def groundtruth_bin():
    """The `groundtruth` program: $GROUNDTRUTH_BIN, else target/release or target/debug."""
    env = os.environ.get("GROUNDTRUTH_BIN")
    if env:
        return env
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
    for profile in ("release", "debug"):
        p = target / profile / "groundtruth"
        if p.is_file():
            return str(p)
    return shutil.which("groundtruth")


@pytest.fixture(scope="session")
def cli():
    """Runs the command-line program; skips (or, with GT_REQUIRE_CLI=1 as CI sets it, fails) when
    it is not built."""
    exe = groundtruth_bin()
    if exe is None:
        if os.environ.get("GT_REQUIRE_CLI") == "1":
            pytest.fail("the groundtruth program is not built (cargo build --release)")
        pytest.skip("the groundtruth program is not built (cargo build --release)")

    def run(*args):
        return subprocess.run([exe, *args], check=True, capture_output=True, text=True)

    return run


@pytest.fixture(scope="session")
def ramp_hdl():
    """A 12 deg down ramp 5 m ahead, HDL-64E at 1.9 m (the README's scenario), measured ranges."""
    (frame,) = gt.scan("ramp", "hdl64e-roof", params={"slope_deg": -12.0, "distance_m": 5.0}, mount={"z_m": 1.9})
    return frame


@pytest.fixture(scope="session")
def flat_vlp():
    (frame,) = gt.scan("flat", "vlp16-roof", ideal=True)
    return frame
