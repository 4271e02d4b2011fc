"""scan(): shapes, dtypes, no-return cells, determinism, scene and rig resolution."""

import math

import numpy as np
import pytest

import groundtruth as gt


def test_grid_shapes_and_dtypes(ramp_hdl):
    f = ramp_hdl
    assert (f.rows, f.cols, f.planes) == (64, 2083, 1)
    assert f.shape == (64, 2083)
    expected = {
        "xyz": (np.float32, (64, 2083, 3)),
        "normal": (np.float32, (64, 2083, 3)),
        "range": (np.float32, (64, 2083)),
        "intensity": (np.float32, (64, 2083)),
        "time": (np.float64, (64, 2083)),
        "ring": (np.uint16, (64, 2083)),
        "column": (np.uint32, (64, 2083)),
        "sensor": (np.uint8, (64, 2083)),
        "echo": (np.uint8, (64, 2083)),
        "label": (np.uint16, (64, 2083)),
        "instance": (np.uint32, (64, 2083)),
        "ground": (np.bool_, (64, 2083)),
        "valid": (np.bool_, (64, 2083)),
    }
    for name, (dtype, shape) in expected.items():
        a = getattr(f, name)
        assert a.dtype == dtype, name
        assert a.shape == shape, name
        assert a.flags.c_contiguous, name


def test_no_return_cells_are_nan_and_counts_agree(ramp_hdl):
    f = ramp_hdl
    valid = f.valid
    assert np.array_equal(valid, np.isfinite(f.range))
    assert np.array_equal(valid, np.isfinite(f.xyz).all(axis=2))
    assert np.isnan(f.xyz[~valid]).all()
    assert int(valid.sum()) == f.returns == 115401
    assert int(f.ground.sum()) == f.ground_returns == 101506
    assert not (f.ground & ~valid).any()
    # Ground truth = the ground classes (road 40, parking 44, sidewalk 48, other-ground 49,
    # lane-marking 60, terrain 72).
    assert np.array_equal(f.ground, valid & np.isin(f.label, [40, 44, 48, 49, 60, 72]))
    # Normals of returns are unit vectors.
    n = np.linalg.norm(f.normal[valid], axis=1)
    assert np.allclose(n, 1.0, atol=1e-4)
    # Row 0 is the lowest beam: ring elevations go up with the row (HDL-64E, rows sorted).
    assert f.rig == "hdl64e-roof" and f.family == "ramp" and f.seed == 0


def test_points_and_index_map(ramp_hdl):
    f = ramp_hdl
    pts, cells = f.points()
    assert pts.dtype == np.float32 and pts.shape == (f.returns, 4)
    assert cells.dtype == np.int64 and cells.shape == (f.returns,)
    assert np.all(np.diff(cells) > 0)  # grid order
    assert np.array_equal(f.xyz.reshape(-1, 3)[cells], pts[:, :3])
    assert np.array_equal(f.intensity.reshape(-1)[cells], pts[:, 3])
    assert np.array_equal(np.flatnonzero(f.valid), cells)


def test_deterministic_and_seeded():
    (a,) = gt.scan("city", "vlp16-roof", seed=3)
    (b,) = gt.scan("city", "vlp16-roof", seed=3)
    (c,) = gt.scan("city", "vlp16-roof", seed=4)
    assert np.array_equal(a.range, b.range, equal_nan=True)
    assert np.array_equal(a.label, b.label)
    assert not np.array_equal(a.range, c.range, equal_nan=True)


def test_frames_speed_and_ideal():
    frames = gt.scan("flat", "vlp16-roof", frames=3, speed=10.0, ideal=True)
    assert [f.index for f in frames] == [0, 1, 2]
    # 10 Hz, 10 m/s: the vehicle moves 1 m per frame.
    x = [float(f.world_from_vehicle[0, 3]) for f in frames]
    assert x == pytest.approx([0.0, 1.0, 2.0], abs=1e-4)
    # Ideal ranges: ground returns lie at z = 0 exactly (within float error).
    f = frames[0]
    assert np.abs(f.xyz[f.ground][:, 2]).max() < 1e-3


def test_scene_by_family_toml_text_and_path(tmp_path):
    text = 'version = 1\nfamily = "ramp"\n[params]\nslope_deg = 8.0\n'
    (by_text,) = gt.scan(text, "vlp16-roof", ideal=True)
    p = tmp_path / "ramp8.toml"
    p.write_text(text)
    (by_path,) = gt.scan(str(p), "vlp16-roof", ideal=True)
    (by_family,) = gt.scan("ramp", "vlp16-roof", params={"slope_deg": 8.0}, ideal=True)
    assert by_text.family == by_path.family == by_family.family == "ramp"
    assert np.array_equal(by_text.range, by_path.range, equal_nan=True)
    assert np.array_equal(by_text.range, by_family.range, equal_nan=True)


def test_rig_by_toml_text_and_mount():
    rig = '[[sensors]]\nname = "front"\nmount = { x_m = 3.7, y_m = 0.0, z_m = 0.5, pitch_deg = 1.0 }\nspec = { model = "ibeo-lux" }\n'
    (f,) = gt.scan("flat", rig)
    # The LUX reports up to 3 echoes: echo plane k is rows k*4 .. (k+1)*4 of the grid.
    assert (f.rows, f.cols, f.planes) == (4, 441, 3)
    assert f.shape == (12, 441)
    assert (f.echo[4:][f.valid[4:]] > 0).all() and (f.echo[:4] == 0).all()
    (ideal,) = gt.scan("flat", rig, ideal=True)
    assert ideal.shape == (4, 441)
    # A mount override moves the sensor: from 3 m up the nearest ground return is farther away.
    (low,) = gt.scan("flat", "vlp16-roof", mount={"z_m": 1.0}, ideal=True)
    (high,) = gt.scan("flat", "vlp16-roof", mount={"z_m": 3.0}, ideal=True)
    near = lambda f: float(np.nanmin(np.hypot(f.xyz[..., 0], f.xyz[..., 1])[f.ground]))
    assert near(high) > 2.5 * near(low)


def test_lists_of_names():
    assert "ramp-up" in gt.SCENES and "basin" in gt.SCENES
    assert "ramp" in gt.FAMILIES and "hill" in gt.FAMILIES
    assert "os1-128-roof" in gt.RIGS
    assert "nitsch" in gt.METHODS and "mcdaniel" in gt.METHODS
    assert "ramp-surface" in gt.REGIONS
    assert math.isfinite(float(gt.__version__.split(".")[0]))


def test_the_gil_is_released_while_scanning():
    # A Python thread keeps counting while another scans: with the GIL held through the Rust call
    # it would not run at all during the scan.
    import threading

    count = [0]
    stop = threading.Event()

    def spin():
        while not stop.is_set():
            count[0] += 1

    t = threading.Thread(target=spin)
    t.start()
    try:
        before = count[0]
        gt.scan("city", "os1-64-roof")
        during = count[0] - before
    finally:
        stop.set()
        t.join()
    assert during > 20_000, during
