"""Round trips against the command-line program's files: the same scan through `groundtruth scan`
and through `groundtruth.scan` gives byte-identical PCD, PLY, KITTI and LAS files, the readers give
back the same counts and labels, and `classify` gives the CLI's `.ground` bytes."""

import filecmp
import json

import numpy as np
import pytest

import groundtruth as gt

SCAN_ARGS = dict(seed=2, frames=2, speed=5.0)


@pytest.fixture(scope="module")
def cli_dir(cli, tmp_path_factory):
    d = tmp_path_factory.mktemp("cli")
    cli(
        "scan", "--scene", "ramp-up", "--rig", "vlp16-roof", "--seed", "2", "--frames", "2", "--speed", "5",
        "--format", "pcd,ply,kitti,las", "--out", str(d / "scan"),
    )  # fmt: skip
    cli("classify", "--method", "nitsch", "--input", str(d / "scan"), "--out", str(d / "ground"))
    cli("classify", "--method", "grid", "--input", str(d / "scan"), "--out", str(d / "grid"))
    return d


@pytest.fixture(scope="module")
def frames():
    return gt.scan("ramp-up", "vlp16-roof", **SCAN_ARGS)


def test_manifest_counts(cli_dir, frames):
    manifest = json.loads((cli_dir / "scan" / "manifest.json").read_text())
    assert len(manifest["frames"]) == len(frames) == 2
    for entry, f in zip(manifest["frames"], frames):
        assert (entry["rows"], entry["cols"]) == f.shape
        assert entry["returns"] == f.returns
        assert entry["ground_returns"] == f.ground_returns
        assert np.allclose(np.array(entry["world_from_vehicle"]), f.world_from_vehicle, atol=1e-6)


@pytest.mark.parametrize("fmt,ext", [("pcd", "pcd"), ("ply", "ply"), ("kitti", "bin"), ("las", "las")])
def test_written_files_are_the_cli_files(cli_dir, frames, tmp_path, fmt, ext):
    for f in frames:
        stem = f"frame_{f.index:06d}"
        n = gt.write(f, tmp_path / f"{stem}.{ext}", fmt)
        assert n == (f.shape[0] * f.shape[1] if fmt == "pcd" else f.returns)
        extra = ["label", "calib.txt"] if fmt == "kitti" else []
        for e in [ext, *extra]:
            assert filecmp.cmp(tmp_path / f"{stem}.{e}", cli_dir / "scan" / f"{stem}.{e}", shallow=False), e
    # The format follows from the extension when not given.
    assert gt.write(frames[0], tmp_path / "auto.bin") == frames[0].returns
    assert filecmp.cmp(tmp_path / "auto.bin", cli_dir / "scan" / "frame_000000.bin", shallow=False)


def test_read_the_cli_pcd_gives_the_same_grid(cli_dir, frames):
    for f in frames:
        r = gt.read(cli_dir / "scan" / f"frame_{f.index:06d}.pcd")
        assert r.shape == f.shape and r.returns == f.returns and r.ground_returns == f.ground_returns
        assert np.array_equal(r.xyz, f.xyz, equal_nan=True)
        assert np.array_equal(r.range, f.range, equal_nan=True)
        for name in ("label", "instance", "ground", "ring", "column", "echo", "sensor", "intensity", "time"):
            assert np.array_equal(getattr(r, name), getattr(f, name)), name
        assert np.allclose(r.normal, f.normal, atol=1e-6)
        # Regions from the file's labels equal those of the scan.
        for region in ("ground", "non-ground", "class:road", "range:0-10"):
            assert np.array_equal(r.region(region), f.region(region)), region
        # Family regions need the scene: a file has none.
        with pytest.raises(ValueError, match="ramp"):
            r.region("ramp-surface")


def test_read_the_cli_kitti_ply_las_same_counts_and_labels(cli_dir, frames):
    for f in frames:
        stem = f"frame_{f.index:06d}"
        labels = np.bincount(f.label[f.valid], minlength=256)
        # As stored: one row in file order (ordered reading is test_read_ordered.py's).
        for ext in ("bin", "ply", "las"):
            r = gt.read(cli_dir / "scan" / f"{stem}.{ext}", ordered=False)
            assert r.shape == (1, f.returns), ext
            assert r.returns == f.returns and r.ground_returns == f.ground_returns, ext
            assert np.array_equal(np.bincount(r.label[r.valid], minlength=256), labels), ext
        # PLY and LAS hold the returns in grid order: the same points, labels, instances, rings.
        for ext in ("ply", "las"):
            r = gt.read(cli_dir / "scan" / f"{stem}.{ext}", ordered=False)
            pts, cells = f.points()
            assert np.allclose(r.xyz[0], pts[:, :3], atol=1e-4), ext
            for name in ("label", "instance", "ground", "ring"):
                assert np.array_equal(getattr(r, name)[0], getattr(f, name).reshape(-1)[cells]), (ext, name)
        # The .label file itself: class | instance << 16 per point of the .bin.
        raw = np.fromfile(cli_dir / "scan" / f"{stem}.label", dtype="<u4")
        assert len(raw) == f.returns
        assert np.array_equal(np.bincount(raw & 0xFFFF, minlength=256), labels)


def test_classify_gives_the_cli_ground_files(cli_dir, frames):
    for f in frames:
        cli_ground = np.fromfile(cli_dir / "ground" / f"frame_{f.index:06d}.ground", dtype=np.uint8)
        mine = gt.classify(f, "nitsch")
        assert np.array_equal(cli_ground, mine.reshape(-1).astype(np.uint8))
        # And on the file read back.
        back = gt.classify(gt.read(cli_dir / "scan" / f"frame_{f.index:06d}.pcd"))
        assert np.array_equal(back, mine)


def test_classify_over_frames_gives_the_cli_grid_files(cli_dir, frames):
    # `grid` accumulates its world map over the frames: one method instance over the list, in order.
    decisions = gt.classify(frames, "grid")
    assert isinstance(decisions, list) and len(decisions) == 2
    for f, d in zip(frames, decisions):
        cli_ground = np.fromfile(cli_dir / "grid" / f"frame_{f.index:06d}.ground", dtype=np.uint8)
        assert np.array_equal(cli_ground, d.reshape(-1).astype(np.uint8))
