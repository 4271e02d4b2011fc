"""`eval_dataset`: our methods scored on a labelled SemanticKITTI-layout recording, the numbers of
`groundtruth eval dataset --input --json`, and its refusals of bad datasets and options."""

import json
import pathlib

import numpy as np
import pytest

import groundtruth as gt


@pytest.fixture(scope="session")
def dataset(tmp_path_factory, cli):
    """A two-sequence dataset of ours (`groundtruth dataset`): city and hill, 2 frames each."""
    root = tmp_path_factory.mktemp("ds")
    config = root / "d.toml"
    config.write_text(
        "[[sequences]]\nid = 0\nscene = \"city\"\nseed = 3\nrig = \"vlp16-roof\"\nframes = 2\nspeed_m_per_s = 5.0\n"
        "[[sequences]]\nid = 1\nscene = \"hill\"\nseed = 4\nrig = \"os1-64-roof\"\nframes = 2\n"
    )
    out = root / "out"
    cli("dataset", "--config", str(config), "--out", str(out))
    return out


def test_scores_agree_with_the_command_line(dataset, cli, tmp_path):
    doc = gt.eval_dataset(dataset, ["nitsch", "learned"])
    assert set(doc["methods"]) == {"nitsch", "learned"}
    assert doc["protocol"]["name"] == "semantickitti"
    assert doc["range_bands"] == ["0-10m", "10-20m", "20-40m", "40m+"]
    learned = doc["methods"]["learned"]
    assert len(learned["frames"]) == 4
    pooled = learned["pooled"]
    assert pooled["tp"] + pooled["fp"] + pooled["tn"] + pooled["fn"] == pooled["points"] > 40_000
    # Our own scenes, the bundled model: at least as good as nitsch, and good.
    assert pooled["f1"] >= 0.97, pooled
    assert pooled["f1"] >= doc["methods"]["nitsch"]["pooled"]["f1"] - 1e-9
    # The command line writes the same counts.
    out = tmp_path / "s.json"
    cli("eval", "--dataset", str(dataset), "--methods", "nitsch,learned", "--json", str(out))
    theirs = json.loads(out.read_text())
    for m in ("nitsch", "learned"):
        for k in ("tp", "fp", "tn", "fn"):
            assert theirs["methods"][m]["pooled"][k] == doc["methods"][m]["pooled"][k]
    # Protocol choices: `--ground` and the Patchwork++ protocol (vegetation left out).
    roads = gt.eval_dataset(dataset, ["nitsch"], ground=[40, 60], sequences=["00"], max_frames=1)
    assert roads["protocol"]["name"] == "semantickitti+ground"
    assert len(roads["methods"]["nitsch"]["frames"]) == 1
    pw = gt.eval_dataset(dataset, ["nitsch"], protocol="patchworkpp")
    assert 70 in pw["protocol"]["ignored"]
    # More classes left out (WADS's falling snow would be `ignore=[110]`).
    left = gt.eval_dataset(dataset, ["nitsch"], ground=[44, 48, 49, 60, 72], ignore=[40])
    assert left["protocol"]["name"] == "semantickitti+ground+ignore" and 40 in left["protocol"]["ignored"]


def test_bad_datasets_and_options_are_refused(dataset, tmp_path):
    with pytest.raises(FileNotFoundError, match="not a SemanticKITTI-layout dataset"):
        gt.eval_dataset(tmp_path)
    with pytest.raises(ValueError, match="--ground.*41"):
        gt.eval_dataset(dataset, ground=[40, 41])
    with pytest.raises(ValueError, match="--protocol"):
        gt.eval_dataset(dataset, protocol="kitti")
    with pytest.raises(ValueError, match="--ignore.*not ground"):
        gt.eval_dataset(dataset, ignore=[72])
    with pytest.raises(ValueError, match="unknown method"):
        gt.eval_dataset(dataset, ["nope"])
    with pytest.raises(ValueError, match="--sequences.*07"):
        gt.eval_dataset(dataset, sequences=["07"])
    # A model of another method.
    other = tmp_path / "m.json"
    other.write_text(json.dumps({"format": "groundtruth-mcdaniel-linear-svm", "version": 1}))
    with pytest.raises(ValueError, match="a model of the `learned` method"):
        gt.eval_dataset(dataset, ["learned"], model=other)
    # A label file whose count differs from its cloud's, and a sequence without labels.
    seq = tmp_path / "bad" / "sequences" / "00"
    (seq / "velodyne").mkdir(parents=True)
    (seq / "labels").mkdir()
    np.zeros((10, 4), np.float32).tofile(seq / "velodyne" / "000000.bin")
    np.zeros(9, np.uint32).tofile(seq / "labels" / "000000.label")
    with pytest.raises(ValueError, match="9 labels.*10 points"):
        gt.eval_dataset(tmp_path / "bad", ["nitsch"])
    for f in (seq / "labels").iterdir():
        f.unlink()
    (seq / "labels").rmdir()
    with pytest.raises(FileNotFoundError, match="labels"):
        gt.eval_dataset(pathlib.Path(tmp_path / "bad"), ["nitsch"])


def test_the_learned_method_keeps_the_down_ramp(ramp_hdl):
    # The README's scenario: the bundled model keeps the ramp surface, and calls the whole frame
    # at least as well as nitsch.
    learned = gt.classify(ramp_hdl, "learned")
    assert learned.shape == ramp_hdl.xyz.shape[:2]
    assert gt.score(ramp_hdl, learned, region="ramp-surface").recall >= 0.95
    assert gt.score(ramp_hdl, learned).f1 >= gt.score(ramp_hdl, gt.classify(ramp_hdl, "nitsch")).f1 - 0.005
