"""Bad input raises ValueError / TypeError / OSError naming the field; nothing crashes."""

import math

import numpy as np
import pytest

import groundtruth as gt


@pytest.mark.parametrize(
    "kwargs,exc,match",
    [
        (dict(scene=1, rig="vlp16-roof"), TypeError, "scene"),
        (dict(scene="no-such-scene", rig="vlp16-roof"), ValueError, "scene: unknown scene `no-such-scene`"),
        (dict(scene="flat", rig="no-such-rig"), ValueError, "rig: unknown rig `no-such-rig`"),
        (dict(scene="flat", rig=None), TypeError, "rig"),
        (dict(scene="no/such/scene.toml", rig="vlp16-roof"), FileNotFoundError, "no/such/scene.toml"),
        (dict(scene="ramp", rig="vlp16-roof", params={"slope_deg": math.nan}), ValueError, "params.slope_deg"),
        (dict(scene="ramp", rig="vlp16-roof", params={"slope_deg": math.inf}), ValueError, "params.slope_deg"),
        (dict(scene="ramp", rig="vlp16-roof", params={"slope_deg": 30.0}), ValueError, "slope_deg"),
        (dict(scene="ramp", rig="vlp16-roof", params={"no_such_field": 1.0}), ValueError, "no_such_field"),
        (dict(scene="ramp", rig="vlp16-roof", params={"slope_deg": [1.0]}), TypeError, "params.slope_deg"),
        (dict(scene="ramp", rig="vlp16-roof", params={3: 1.0}), TypeError, "params"),
        (dict(scene="ramp", rig="vlp16-roof", params=[("slope_deg", 1.0)]), TypeError, "params"),
        (dict(scene="flat", rig="vlp16-roof", mount={"z_m": math.nan}), ValueError, "mount.z_m"),
        (dict(scene="flat", rig="vlp16-roof", mount={"z_m": 150.0}), ValueError, "mount.z_m"),
        (dict(scene="flat", rig="vlp16-roof", mount={"z_m": "high"}), TypeError, "mount.z_m"),
        (dict(scene="flat", rig="vlp16-roof", mount={"height": 1.0}), ValueError, "mount.height"),
        (dict(scene="flat", rig="vlp16-roof", mount={"sensor": 3, "z_m": 1.0}), ValueError, "sensor"),
        (dict(scene="flat", rig="vlp16-roof", seed=-1), ValueError, "seed"),
        (dict(scene="flat", rig="vlp16-roof", seed="7"), TypeError, "seed"),
        (dict(scene="flat", rig="vlp16-roof", seed=1.5), TypeError, "seed"),
        (dict(scene="flat", rig="vlp16-roof", frames=0), ValueError, "frames"),
        (dict(scene="flat", rig="vlp16-roof", frames=True), TypeError, "frames"),
        (dict(scene="flat", rig="vlp16-roof", speed_m_per_s=math.nan), ValueError, "speed_m_per_s"),
        (dict(scene="flat", rig="vlp16-roof", speed_m_per_s=500.0), ValueError, "speed_m_per_s"),
        (dict(scene="flat", rig="vlp16-roof", speed=500.0), ValueError, "speed"),
        (dict(scene="flat", rig="vlp16-roof", speed="fast"), TypeError, "speed"),
        (dict(scene="version = 1\nfamily = 'nope'\n", rig="vlp16-roof"), ValueError, "nope"),
        (dict(scene="flat", rig="[[sensors]]\nname = 1\n"), ValueError, "rig TOML"),
    ],
)
def test_scan_bad_input(kwargs, exc, match):
    with pytest.raises(exc, match=match):
        gt.scan(**kwargs)


# The scan spec's own messages: the same words `groundtruth scan --spec`, dataset and sweep files
# and the Rust builder give (scenario/src/spec/tests.rs, tests/cli_spec.rs).
@pytest.mark.parametrize(
    "kwargs,match",
    [
        (dict(colour=1), "unknown field `colour`, expected one of"),
        (dict(yaw_rate=0.3), "invalid value for `yaw_rate`: a key without the unit every front end takes"),
        (dict(mount={"z_m": 150.0}), r"invalid value for `mount.z_m`: 150 \(allowed: -100 ..= 100\)"),
        (dict(mount={"height": 1.0}), "unknown field `height`"),
        (dict(yaw_rate_deg_per_s=200.0), r"invalid value for `yaw_rate_deg_per_s`: 200 \(allowed: -114.59 ..= 114.59\)"),
    ],
)
def test_scan_spec_messages(kwargs, match):
    with pytest.raises(ValueError, match=match):
        gt.scan("flat", "vlp16-roof", **kwargs)


def test_speed_is_deprecated_but_works():
    with pytest.warns(DeprecationWarning, match="speed_m_per_s"):
        (old,) = gt.scan("flat", "vlp16-roof", speed=5.0, ideal=True)
    (new,) = gt.scan("flat", "vlp16-roof", speed_m_per_s=5.0, ideal=True)
    assert np.array_equal(old.range, new.range, equal_nan=True)


def test_the_builtin_scene_is_reachable():
    (f,) = gt.scan("flat-objects", "vlp16-roof", ideal=True)
    assert f.returns > 1000


@pytest.fixture(scope="module")
def frame():
    (f,) = gt.scan("flat", "vlp16-roof", ideal=True)
    return f


@pytest.mark.parametrize(
    "decisions,exc,match",
    [
        (lambda f: np.zeros(f.shape, dtype=np.int64), TypeError, "decisions: expected dtype bool, got"),
        (lambda f: np.zeros(f.shape, dtype=np.float32), TypeError, "decisions: expected dtype bool"),
        (lambda f: [True] * f.returns, TypeError, "decisions: expected a numpy bool array, got list"),
        (lambda f: np.zeros(f.returns + 1, dtype=bool), ValueError, "decisions: shape"),
        (lambda f: np.zeros((f.shape[1], f.shape[0]), dtype=bool), ValueError, "decisions: shape"),
        (lambda f: None, TypeError, "decisions"),
    ],
)
def test_score_bad_decisions(frame, decisions, exc, match):
    with pytest.raises(exc, match=match):
        gt.score(frame, decisions(frame))


def test_bad_regions(frame):
    ok = np.zeros(frame.shape, dtype=bool)
    with pytest.raises(ValueError, match="region: `roofs`: unknown region"):
        gt.score(frame, ok, region="roofs")
    with pytest.raises(ValueError, match="needs a `ramp` scene"):
        frame.region("ramp-surface")
    with pytest.raises(ValueError, match="region"):
        frame.region("class:no-such-class")
    with pytest.raises(ValueError, match="RangeBand"):
        frame.region("range:10-5")
    with pytest.raises(ValueError, match="region"):
        frame.region("range:a-b")
    with pytest.raises(ValueError, match="holds no return"):
        gt.score(frame, ok, region="vehicle-roofs")
    with pytest.raises(TypeError, match="region"):
        gt.score(frame, ok, region=3)
    with pytest.raises(TypeError):
        gt.score("not a frame", ok)


def test_bad_classify(frame, tmp_path):
    with pytest.raises(ValueError, match="no-such-method"):
        gt.classify(frame, "no-such-method")
    with pytest.raises(ValueError, match="model: .* applies to `mcdaniel` and `learned`, not to `nitsch`"):
        gt.classify(frame, "nitsch", model="m.json")
    with pytest.raises(FileNotFoundError, match="model"):
        gt.classify(frame, "learned", model=tmp_path / "missing.json")
    with pytest.raises(FileNotFoundError, match="model"):
        gt.classify(frame, "mcdaniel", model=tmp_path / "missing.json")
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    with pytest.raises(ValueError, match="bad.json"):
        gt.classify(frame, "mcdaniel", model=bad)
    with pytest.raises(ValueError, match="bad.json"):
        gt.classify(frame, "learned", model=bad)
    with pytest.raises(TypeError, match="method"):
        gt.classify(frame, 3)
    with pytest.raises(TypeError, match="frame: expected a Frame or a list of Frames, got str"):
        gt.classify("frame.pcd")
    with pytest.raises(TypeError, match="frame: expected a Frame or a list of Frames, got a list holding int"):
        gt.classify([frame, 1])


def test_bad_files(frame, tmp_path):
    with pytest.raises(FileNotFoundError, match="missing.pcd"):
        gt.read(tmp_path / "missing.pcd")
    txt = tmp_path / "cloud.txt"
    txt.write_text("1 2 3\n")
    with pytest.raises(ValueError, match="path: .*unknown extension"):
        gt.read(txt)
    for ext, content in [("pcd", b"garbage"), ("ply", b"ply\nformat nonsense\n"), ("bin", b"\x00" * 17), ("las", b"LASF" + b"\x00" * 40)]:
        p = tmp_path / f"bad.{ext}"
        p.write_bytes(content)
        with pytest.raises(ValueError, match=f"bad.{ext}"):
            gt.read(p)
    with pytest.raises(ValueError, match="format: `xyz`"):
        gt.write(frame, tmp_path / "out.pcd", "xyz")
    with pytest.raises(ValueError, match="format"):
        gt.write(frame, tmp_path / "out.unknown")
    with pytest.raises((OSError, ValueError), match="no/such/dir"):
        gt.write(frame, tmp_path / "no/such/dir/out.pcd")
    with pytest.raises(TypeError, match="path"):
        gt.read(3)


def test_classify_an_unorganized_file_is_refused_not_crashed(tmp_path):
    # A KITTI .bin read as stored is a 1 x N cloud in file order; our methods need the grid (read
    # ordered, the default, recovers it as the command line's `classify` does).
    (f,) = gt.scan("flat", "vlp16-roof")
    gt.write(f, tmp_path / "f.bin")
    back = gt.read(tmp_path / "f.bin", ordered=False)
    assert back.shape == (1, f.returns)
    with pytest.raises(ValueError, match="too small"):
        gt.classify(back)
    # Ordered: `flat` lights the lower 8 of the 16 beams, an unnamed 8-ring sensor, as the CLI says.
    ordered = gt.read(tmp_path / "f.bin")
    assert ordered.shape == (8, f.cols) and ordered.ordering["sensor"]["model"] is None
    assert gt.classify(ordered).shape == ordered.shape
