"""regions(), score() and classify() against the Rust scenario API's definitions and counts."""

import math

import numpy as np
import pytest

import groundtruth as gt


def test_ramp_surface_lies_on_the_ramp_plane():
    # The Rust doc test of Region, from Python: every ramp-surface return is ground and lies on
    # the 10 deg plane that starts 15 m ahead (the family's default distance).
    (f,) = gt.scan("ramp", "vlp16-roof", params={"slope_deg": 10.0}, ideal=True)
    m = f.region("ramp-surface")
    assert m.dtype == np.bool_ and m.shape == f.shape
    assert m.sum() > 100
    assert f.ground[m].all()
    p = f.xyz[m]
    assert np.abs(p[:, 2] - (p[:, 0] - 15.0) * math.tan(math.radians(10.0))).max() < 0.05


def test_basin_regions():
    (f,) = gt.scan("basin", "os1-64-roof", params={"depth_m": 2.0}, ideal=True)
    r = gt.regions(f)
    assert {"basin-floor", "beyond-basin", "ground", "all"} <= set(r)
    assert "ramp-surface" not in r
    floor = f.xyz[r["basin-floor"]]
    assert len(floor) > 50
    assert np.abs(floor[:, 2] + 2.0).max() <= 0.05
    assert r["beyond-basin"].sum() > 100
    assert np.array_equal(r["all"], f.valid)
    assert np.array_equal(r["ground"], f.ground)
    assert np.array_equal(r["non-ground"], f.valid & ~f.ground)


def test_elevated_regions_and_generic_regions():
    (f,) = gt.scan("elevated", "vlp16-roof")
    roofs = f.region("vehicle-roofs")
    assert roofs.sum() > 50
    assert not f.ground[roofs].any()
    assert np.isin(f.label[roofs], [10, 18, 20]).all()
    assert (roofs <= f.region("flat-raised-tops")).all()
    cars = f.region("class:car")
    assert np.array_equal(cars, f.valid & (f.label == 10))
    assert np.array_equal(f.region("class:10"), cars)
    band = f.region("range:5-10")
    assert np.array_equal(band, f.valid & (f.range >= 5) & (f.range < 10))
    inst = int(f.instance[roofs][0])
    assert np.array_equal(f.region(f"instance:{inst}"), f.valid & (f.instance == inst))


def test_score_counts_equal_numpy_confusion(ramp_hdl):
    f = ramp_hdl
    pts, cells = f.points()
    mine = pts[:, 2] < 0.25
    cell_d = np.zeros(f.shape, dtype=bool)
    cell_d.reshape(-1)[cells] = mine
    for region in (None, "ground", "ramp-surface", "flat-raised-tops", "range:0-20"):
        m = f.region(region or "all")
        g = f.ground
        s = gt.score(f, mine, region=region)
        assert (s.tp, s.fp, s.tn, s.fn) == (
            int((m & g & cell_d).sum()),
            int((m & ~g & cell_d).sum()),
            int((m & ~g & ~cell_d).sum()),
            int((m & g & ~cell_d).sum()),
        )
        # The same decisions as cells (grid shape, flat) score the same.
        assert gt.score(f, cell_d, region=region).as_dict() == pytest.approx(s.as_dict(), nan_ok=True)
        assert gt.score(f, cell_d.reshape(-1), region=region).as_dict() == pytest.approx(s.as_dict(), nan_ok=True)
    s = gt.score(f, mine)
    tp, fp, tn, fn = s.tp, s.fp, s.tn, s.fn
    assert s.returns == f.returns
    assert s.accuracy == pytest.approx((tp + tn) / (tp + fp + tn + fn))
    assert s.fpr == pytest.approx(fp / (fp + tn))
    assert s.precision == pytest.approx(tp / (tp + fp))
    assert s.recall == pytest.approx(tp / (tp + fn))
    assert s.f1 == pytest.approx(2 * tp / (2 * tp + fp + fn))
    assert s.iou == pytest.approx(tp / (tp + fp + fn))


def test_rates_without_denominator_are_nan(ramp_hdl):
    s = gt.score(ramp_hdl, np.ones(ramp_hdl.shape, dtype=bool), region="ground")
    assert s.recall == 1.0 and math.isnan(s.fpr)


def test_classify_matches_the_rust_api_figures(ramp_hdl):
    # Scenario::score_method("nitsch", &Region::RampSurface) of the README scenario: recall >= 0.95.
    d = gt.classify(ramp_hdl)
    assert d.dtype == np.bool_ and d.shape == ramp_hdl.shape
    assert not (d & ~ramp_hdl.valid).any()
    s = gt.score(ramp_hdl, d, region="ramp-surface")
    assert s.recall >= 0.95, s
    assert (s.tp, s.fn) == (5439, 50)
    for method in gt.METHODS:
        dm = gt.classify(ramp_hdl, method)
        assert dm.shape == ramp_hdl.shape, method
        assert gt.score(ramp_hdl, dm, region="ground").recall > 0.5, method


def test_classify_is_deterministic(flat_vlp):
    assert np.array_equal(gt.classify(flat_vlp, "ransac"), gt.classify(flat_vlp, "ransac"))
    assert gt.score(flat_vlp, gt.classify(flat_vlp), region="ground").recall > 0.99


def test_pooled_score_over_the_frames_of_a_scan():
    frames = gt.scan("basin", "vlp16-roof", frames=3, speed=8.0)
    decisions = [gt.classify(f) for f in frames]
    pooled = gt.score(frames, decisions, region="beyond-basin")
    per_frame = [gt.score(f, d, region="beyond-basin") for f, d in zip(frames, decisions)]
    for k in ("tp", "fp", "tn", "fn"):
        assert getattr(pooled, k) == sum(getattr(s, k) for s in per_frame), k
    assert pooled.returns > 1000, pooled
    # Per-return decisions work per frame too.
    points = [f.points()[0][:, 2] < 0.3 for f in frames]
    assert gt.score(tuple(frames), points).returns == sum(f.returns for f in frames)
    with pytest.raises(ValueError, match="frame: pooled scores take all 3 frames"):
        gt.score(frames[:2], decisions[:2])
    with pytest.raises(ValueError, match="frame: pooled scores take all 3 frames"):
        gt.score(frames[::-1], decisions)
    with pytest.raises(ValueError, match="decisions: 2 arrays for 3 frames"):
        gt.score(frames, decisions[:2])
    with pytest.raises(TypeError, match="decisions: expected a list"):
        gt.score(frames, decisions[0])
    with pytest.raises(TypeError, match="frame: expected a Frame, or a list"):
        gt.score([frames[0], "x"], decisions)
    with pytest.raises(ValueError, match="frame: an empty list"):
        gt.score([], [])


def test_the_readme_example():
    # python/README.md and the package docstring: a flat-world toy loses the down ramp, nitsch keeps it.
    (frame,) = gt.scan("ramp", "hdl64e-roof", params={"slope_deg": -12.0, "distance_m": 5.0}, mount={"z_m": 1.9})
    points, _cells = frame.points()
    s = gt.score(frame, abs(points[:, 2]) < 0.25, region="ramp-surface")
    assert (s.tp, s.fn, s.returns) == (983, 4506, 5489)
    assert round(s.recall, 2) == 0.18
    assert gt.score(frame, gt.classify(frame, "nitsch"), region="ramp-surface").recall >= 0.95


def test_strided_and_fortran_decisions_score_like_contiguous(ramp_hdl):
    d = gt.classify(ramp_hdl)
    want = gt.score(ramp_hdl, d).as_dict()
    assert gt.score(ramp_hdl, np.asfortranarray(d)).as_dict() == pytest.approx(want, nan_ok=True)
    wide = np.zeros((d.shape[0], 2 * d.shape[1]), dtype=bool)
    wide[:, ::2] = d
    assert gt.score(ramp_hdl, wide[:, ::2]).as_dict() == pytest.approx(want, nan_ok=True)
    assert gt.score(ramp_hdl, d[::-1][::-1]).as_dict() == pytest.approx(want, nan_ok=True)
