"""`read()` orders recordings as `groundtruth classify` does (one front door, `classifier::recording`):
a ring-less KITTI `.bin` written from our own scans reads back in the scanner's rows x columns,
`learned` decides on it as the command line does, `ordered=False` keeps the stored `1 x N` grid,
and bad arguments raise errors that name them."""

import re

import numpy as np
import pytest

import groundtruth as gt

# Roof rigs and the catalogue's sensor their ring-less .bin is matched to.
RIGS = {"vlp16-roof": "vlp16", "hdl64e-roof": "hdl64e", "os1-128-roof": "os1-128"}
SEED = 11  # a scene seed no other test uses


@pytest.fixture(scope="module")
def bins(tmp_path_factory):
    """rig -> (scanned frame, its ring-less KITTI .bin written by `write`)."""
    out = {}
    d = tmp_path_factory.mktemp("bins")
    for rig in RIGS:
        (f,) = gt.scan("rural", rig, seed=SEED)
        path = d / f"{rig}.bin"
        assert gt.write(f, path) == f.returns
        out[rig] = (f, path)
    return out


@pytest.mark.parametrize("rig", list(RIGS))
def test_a_ring_less_bin_reads_back_in_the_scanners_grid(bins, rig):
    f, path = bins[rig]
    back = gt.read(path)
    assert back.shape == (f.rows, f.cols), back.ordering["summary"]
    o = back.ordering
    assert o["sensor"]["model"] == RIGS[rig], o["summary"]
    assert (o["sensor"]["rows"], o["sensor"]["columns"]) == (f.rows, f.cols)
    assert o["rows"] == f.rows and o["cols"] == f.cols and o["planes"] == 1
    assert o["points"] == f.returns and o["layout"] == "kitti-bin" and o["layout_by"] == "name"
    assert f"matched: {RIGS[rig]}" in o["summary"] and o["summary"].startswith(f"ordered into {f.rows} x {f.cols}")
    # Every point got a cell, and the labels came along with the points.
    cells = back.cell_of_point
    assert cells.shape == (f.returns,) and (cells >= 0).all()
    assert o["placed"] + o["moved"] + o["stacked"] + o["shared"] == f.returns
    assert back.ground_returns + o["shared"] >= f.ground_returns >= back.ground_returns - o["shared"]
    labels = np.fromfile(path.with_suffix(".label"), dtype="<u4") & 0xFFFF
    assert np.array_equal(back.label.reshape(-1)[cells], labels)


def test_learned_on_a_read_back_vlp16_bin_scores_as_on_the_scan(bins):
    f, path = bins["vlp16-roof"]
    back = gt.read(path)
    s = gt.score(back, gt.classify(back, "learned"))
    assert s.f1 >= 0.98, s
    on_scan = gt.score(f, gt.classify(f, "learned")).f1
    assert abs(s.f1 - on_scan) <= 0.005, (s.f1, on_scan)


@pytest.mark.parametrize("rig", list(RIGS))
def test_learned_decides_as_the_cli_on_a_read_back_bin(bins, cli, tmp_path, rig):
    _, path = bins[rig]
    back = gt.read(path)
    mine = back.decisions_per_point(gt.classify(back, "learned"))
    out = tmp_path / "out"
    run = cli("classify", "--input", str(path), "--method", "learned", "--out", str(out))
    theirs = np.fromfile(out / "frame_000000.ground", dtype=np.uint8)
    assert mine.dtype == np.uint8 and mine.shape == theirs.shape
    assert np.array_equal(mine, theirs), int((mine != theirs).sum())
    # The CLI prints the same ordering report.
    assert f"{path}: {back.ordering['summary']}" in run.stdout.splitlines(), run.stdout
    assert re.search(rf"frame_000000: {len(theirs)} points, {int(mine.sum())} ground", run.stdout), run.stdout


def test_a_rig_orders_by_its_beam_table_and_names_no_match(bins):
    f, path = bins["vlp16-roof"]
    back = gt.read(path, rig="vlp16-roof")
    assert back.shape == (16, f.cols)
    assert back.ordering["sensor"] is None and back.ordering["path"] in ("unfolded", "beam-table")
    # Points in the sensor frame are taken to the vehicle frame by the rig's mount (roof height).
    assert np.nanmin(back.xyz[..., 2]) > np.nanmin(gt.read(path).xyz[..., 2]) + 1.0


def test_ordered_false_reads_as_stored(bins):
    f, path = bins["vlp16-roof"]
    stored = gt.read(path, ordered=False)
    assert stored.shape == (1, f.returns) and stored.ordering is None and stored.cell_of_point is None
    records = np.fromfile(path, dtype="<f4").reshape(-1, 4)
    assert np.array_equal(stored.xyz[0], records[:, :3])
    with pytest.raises(ValueError, match="too small"):
        gt.classify(stored)
    # Cell by cell: one decision per point of the file.
    d = np.zeros(stored.shape, dtype=bool)
    d[0, :3] = True
    assert stored.decisions_per_point(d).tolist()[:4] == [1, 1, 1, 0]


def test_our_own_organized_pcd_reads_as_before(tmp_path):
    (f,) = gt.scan("flat", "vlp16-roof", seed=SEED)
    gt.write(f, tmp_path / "f.pcd")
    ordered, stored = gt.read(tmp_path / "f.pcd"), gt.read(tmp_path / "f.pcd", ordered=False)
    assert ordered.shape == stored.shape == f.shape
    for name in ("xyz", "range", "label", "ring", "column", "ground"):
        assert np.array_equal(getattr(ordered, name), getattr(stored, name), equal_nan=True), name
    assert ordered.ordering["path"] is None and ordered.ordering["summary"].startswith("kept as written")
    assert ordered.cell_of_point is None
    assert np.array_equal(gt.classify(ordered), gt.classify(f))


def test_a_bag_of_a_drivers_layout_is_ordered_message_by_message(tmp_path):
    frames = gt.scan("ramp-up", "vlp16-roof", seed=SEED, frames=2, speed_m_per_s=8.0)
    bag = tmp_path / "bag"
    gt.write(frames, bag, "mcap", layout="velodyne")
    back = gt.read(bag)
    assert len(back) == 2
    for k, (f, b) in enumerate(zip(frames, back)):
        assert b.shape == (f.rows, f.cols), b.ordering["summary"]
        assert b.ordering["topic"] == "/roof/points" and b.ordering["message"] == k and b.index == k
        assert b.ordering["layout"] == "point-cloud2"
        assert b.decisions_per_point(gt.classify(b)).shape == (b.ordering["points"],)
    stored = gt.read(bag, ordered=False)
    assert all(s.ordering is None for s in stored)


def test_bad_arguments_name_themselves(bins, tmp_path):
    _, path = bins["vlp16-roof"]
    with pytest.raises(ValueError, match="^rig: .*nope"):
        gt.read(path, rig="nope")
    with pytest.raises(ValueError, match="^rig: .*single-sensor"):
        gt.read(path, rig="lux-roof-4")
    bad = tmp_path / "bad.yaml"
    bad.write_text("lasers: [oops\n")
    with pytest.raises(ValueError, match="^calibration: "):
        gt.read(path, calibration=bad)
    with pytest.raises(FileNotFoundError, match="^calibration: "):
        gt.read(path, calibration=tmp_path / "missing.yaml")
    for name, value in (("rig", "vlp16-roof"), ("calibration", bad)):
        with pytest.raises(ValueError, match=f"^{name}: .*ordered=False"):
            gt.read(path, ordered=False, **{name: value})
    back = gt.read(path)
    with pytest.raises(ValueError, match="^decisions: "):
        back.decisions_per_point(np.zeros((3, 3), dtype=bool))
    with pytest.raises(TypeError, match="^decisions: "):
        back.decisions_per_point(np.zeros(back.shape, dtype=np.uint8))
    # Points in no order a sensor gives: refused, naming the path and the way out.
    rng = np.random.default_rng(0)
    noise = tmp_path / "noise.bin"
    pts = rng.uniform(-30, 30, size=(20000, 4)).astype("<f4")
    pts[:, 3] = 0.5
    pts.tofile(noise)
    with pytest.raises(ValueError, match=r"^path: .*noise\.bin.*ordered=False"):
        gt.read(noise)
    assert gt.read(noise, ordered=False).shape == (1, 20000)


def test_ring_values_beyond_the_rigs_count_are_refused(tmp_path):
    # An unorganized ASCII PCD with a ring field holding rings 0..31, read as a 16-beam sensor.
    n = 2000
    az = np.linspace(-np.pi, np.pi, n, endpoint=False)
    ring = np.arange(n) % 32
    el = np.deg2rad(-15.0 + ring)
    xyz = np.stack([10 * np.cos(el) * np.cos(az), 10 * np.cos(el) * np.sin(az), 10 * np.sin(el)], axis=1)
    header = (
        "VERSION 0.7\nFIELDS x y z intensity ring\nSIZE 4 4 4 4 2\nTYPE F F F F U\nCOUNT 1 1 1 1 1\n"
        f"WIDTH {n}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\nDATA ascii\n"
    )
    rows = "\n".join(f"{x:.4f} {y:.4f} {z:.4f} 0.5 {r}" for (x, y, z), r in zip(xyz, ring))
    pcd = tmp_path / "rings.pcd"
    pcd.write_text(header + rows + "\n")
    with pytest.raises(ValueError, match=r"^path: .*ring"):
        gt.read(pcd, rig="vlp16-roof")
