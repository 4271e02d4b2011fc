"""ROS 2 bags against real clients from PyPI: what `groundtruth scan --format mcap` and
`groundtruth.write(..., "mcap")` write is decoded by `mcap` + `mcap-ros2-support`, read by `rosbags`
and converted by Rerun's MCAP loader with the manifest's point counts; a bag that `rosbags` writes
(our clouds in the velodyne and ouster drivers' own point layouts, padding included, as a ROS 2
recorder would store them) classifies to the same decisions as the same clouds given as PCD files."""

import json
import pathlib
import shutil
import subprocess
import sys

import numpy as np
import pytest

import groundtruth as gt

mcap_reader = pytest.importorskip("mcap.reader")
mcap_ros2_decoder = pytest.importorskip("mcap_ros2.decoder")
rosbag2 = pytest.importorskip("rosbags.rosbag2")
typesys = pytest.importorskip("rosbags.typesys")

VELODYNE_FIELDS = ["x", "y", "z", "intensity", "ring", "time", "label"]
OUSTER_FIELDS = ["x", "y", "z", "intensity", "t", "reflectivity", "ring", "ambient", "range", "label"]


def scan(cli, out, rig, layout, frames=3):
    cli(
        "scan", "--scene", "ramp-up", "--rig", rig, "--seed", "4", "--frames", str(frames), "--speed", "8",
        "--format", "mcap,pcd", "--pcd-layout", layout, "--out", str(out),
    )  # fmt: skip
    return json.loads((out / "manifest.json").read_text())


@pytest.fixture(scope="module")
def scans(cli, tmp_path_factory):
    d = tmp_path_factory.mktemp("ros2")
    return {
        "velodyne": (d / "v", scan(cli, d / "v", "vlp16-roof", "velodyne")),
        "ouster": (d / "o", scan(cli, d / "o", "os1-64-roof", "ouster")),
        # Four sensors, our layout: one topic per sensor, every field.
        "groundtruth": (d / "g", scan(cli, d / "g", "lux-roof-4", "groundtruth", frames=2)),
    }


def manifest_counts(manifest):
    """Per topic, the point count of every frame's message, from the manifest."""
    out = {}
    for frame in manifest["frames"]:
        for f in frame["files"]:
            if f["format"].startswith("mcap:"):
                out.setdefault(f["format"][5:], []).append(f["points"])
    return out


@pytest.mark.parametrize("layout", ["velodyne", "ouster", "groundtruth"])
def test_mcap_ros2_decoder_decodes_every_message(scans, layout):
    out, manifest = scans[layout]
    counts, stamps, tf = {}, {}, 0
    with open(out / "bag" / "bag_0.mcap", "rb") as f:
        reader = mcap_reader.make_reader(f, decoder_factories=[mcap_ros2_decoder.DecoderFactory()])
        assert reader.get_header().profile == "ros2"
        for schema, channel, message, msg in reader.iter_decoded_messages():
            if schema.name == "sensor_msgs/msg/PointCloud2":
                names = [p.name for p in msg.fields]
                if layout == "velodyne":
                    assert names == VELODYNE_FIELDS and msg.point_step == 26
                elif layout == "ouster":
                    assert names == OUSTER_FIELDS
                else:
                    assert {"x", "y", "z", "label", "ground", "ring", "time"} <= set(names)
                assert len(msg.data) == msg.row_step * msg.height
                counts.setdefault(channel.topic, []).append(msg.width * msg.height)
                stamps.setdefault(channel.topic, []).append(msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9)
            elif channel.topic in ("/tf", "/tf_static"):
                assert schema.name == "tf2_msgs/msg/TFMessage"
                tf += len(msg.transforms)
    assert counts == manifest_counts(manifest)
    for topic, times in stamps.items():
        assert np.allclose(times, [f["start_time_s"] for f in manifest["frames"]], atol=1e-9), topic
    sensors = len(manifest["sensors"])
    assert tf == sensors + len(manifest["frames"])  # the mounts once, then a pose per frame


@pytest.mark.parametrize("layout", ["velodyne", "ouster", "groundtruth"])
def test_rosbags_reads_the_rosbag2_directory(scans, layout):
    out, manifest = scans[layout]
    store = typesys.get_typestore(typesys.Stores.ROS2_HUMBLE)
    counts = {}
    with rosbag2.Reader(out / "bag") as reader:
        assert reader.message_count == sum(len(v) for v in manifest_counts(manifest).values()) + len(
            manifest["frames"]
        ) + 1
        for conn, _, raw in reader.messages():
            msg = store.deserialize_cdr(raw, conn.msgtype)
            if conn.msgtype == "sensor_msgs/msg/PointCloud2":
                counts.setdefault(conn.topic, []).append(msg.width * msg.height)
                assert msg.data.size == msg.row_step * msg.height
    assert counts == manifest_counts(manifest)


def rerun_exe():
    exe = pathlib.Path(sys.executable).parent / "rerun"
    return str(exe) if exe.is_file() else shutil.which("rerun")


def test_rerun_converts_the_bag_with_every_point(scans, tmp_path):
    pytest.importorskip("rerun")
    from rerun.chunk import RrdReader

    exe = rerun_exe()
    if exe is None:
        pytest.skip("rerun's command-line program is not installed")
    for layout in ("velodyne", "groundtruth"):
        out, manifest = scans[layout]
        rrd = tmp_path / f"{layout}.rrd"
        subprocess.run([exe, "mcap", "convert", str(out / "bag" / "bag_0.mcap"), "-o", str(rrd)], check=True)
        counts = {}
        for chunk in RrdReader(rrd).stream():
            batch = chunk.to_record_batch()
            for name in batch.schema.names:
                if name.endswith("Points3D:positions"):
                    column = batch.column(name)
                    counts.setdefault(chunk.entity_path, []).extend(len(column[i]) for i in range(len(column)))
        assert counts == manifest_counts(manifest), layout


# --- a bag written by someone else: rosbags, the drivers' own point layouts -----------------------

PCD_TYPES = {("F", 4): "<f4", ("F", 8): "<f8", ("U", 1): "u1", ("U", 2): "<u2", ("U", 4): "<u4", ("I", 4): "<i4"}
# sensor_msgs/PointField datatypes.
ROS_TYPES = {"<f4": 7, "<f8": 8, "u1": 2, "<u2": 4, "<u4": 6, "<i4": 5}

# The drivers' in-memory point structs (PCL's PCL_ADD_POINT4D pads x y z to 16 bytes): velodyne's
# PointXYZIRT is 32 bytes, ouster-ros' Point 48. Our `label` goes into padding where there is room.
DRIVER_OFFSETS = {
    "velodyne": ({"x": 0, "y": 4, "z": 8, "intensity": 16, "ring": 20, "time": 24, "label": 28}, 32),
    "ouster": (
        {"x": 0, "y": 4, "z": 8, "intensity": 16, "t": 20, "reflectivity": 24, "ring": 26, "ambient": 28, "range": 32,
         "label": 36},
        48,
    ),  # fmt: skip
}


def read_pcd(path):
    """A binary PCD file as (fields, structured array, height, width); enough of the format for ours."""
    raw = path.read_bytes()
    header, pos = {}, 0
    while True:
        end = raw.index(b"\n", pos)
        line = raw[pos:end].decode()
        pos = end + 1
        if line.startswith("#"):
            continue
        key, *values = line.split()
        header[key] = values
        if key == "DATA":
            assert values == ["binary"]
            break
    names = header["FIELDS"]
    dtype = np.dtype(
        [(n, PCD_TYPES[(t, int(s))], (int(c),) if int(c) > 1 else ()) for n, s, t, c in
         zip(names, header["SIZE"], header["TYPE"], header["COUNT"])]
    )  # fmt: skip
    h, w = int(header["HEIGHT"][0]), int(header["WIDTH"][0])
    return names, np.frombuffer(raw[pos:], dtype=dtype, count=h * w), h, w


def write_foreign_bag(store, bag_dir, pcd_files, layout, topic):
    """Writes the PCD frames as PointCloud2 messages with rosbags' own writer and CDR encoder."""
    offsets, step = DRIVER_OFFSETS[layout]
    types = store.types
    PointCloud2, PointField = types["sensor_msgs/msg/PointCloud2"], types["sensor_msgs/msg/PointField"]
    Header, Time = types["std_msgs/msg/Header"], types["builtin_interfaces/msg/Time"]
    with rosbag2.Writer(bag_dir, version=9, storage_plugin=rosbag2.StoragePlugin.MCAP) as writer:
        conn = writer.add_connection(topic, PointCloud2.__msgtype__, typestore=store)
        for k, path in enumerate(pcd_files):
            names, points, h, w = read_pcd(path)
            assert names == list(offsets), names
            data = np.zeros((h * w, step), np.uint8)
            fields = []
            for n in names:
                column = np.ascontiguousarray(points[n])
                size = column.dtype.itemsize
                data[:, offsets[n] : offsets[n] + size] = column.view(np.uint8).reshape(-1, size)
                fields.append(PointField(name=n, offset=offsets[n], datatype=ROS_TYPES[column.dtype.str.replace("|", "")], count=1))
            stamp = Time(sec=k // 10, nanosec=(k % 10) * 100_000_000)
            msg = PointCloud2(
                header=Header(stamp=stamp, frame_id="lidar"), height=h, width=w, fields=fields,
                is_bigendian=False, point_step=step, row_step=step * w, data=data.reshape(-1), is_dense=False,
            )  # fmt: skip
            writer.write(conn, stamp.sec * 10**9 + stamp.nanosec, store.serialize_cdr(msg, msg.__msgtype__))


@pytest.mark.parametrize("layout", ["velodyne", "ouster"])
def test_a_rosbags_bag_classifies_as_its_pcd_files(scans, cli, tmp_path, layout):
    out, manifest = scans[layout]
    store = typesys.get_typestore(typesys.Stores.ROS2_HUMBLE)
    pcds = sorted(out.glob("frame_*.pcd"))
    assert len(pcds) == len(manifest["frames"])
    write_foreign_bag(store, tmp_path / "recorded", pcds, layout, "/points_raw")
    for method in ("nitsch", "learned"):
        cli("classify", "--method", method, "--input", str(tmp_path / "recorded"), "--topic", "/points_raw",
            "--out", str(tmp_path / f"bag-{method}"))  # fmt: skip
        cli("classify", "--method", method, "--input", str(out), "--out", str(tmp_path / f"pcd-{method}"))
        for k, pcd in enumerate(pcds):
            from_bag = (tmp_path / f"bag-{method}" / f"frame_{k:06d}.ground").read_bytes()
            from_pcd = (tmp_path / f"pcd-{method}" / f"{pcd.stem}.ground").read_bytes()
            assert len(from_bag) == len(read_pcd(pcd)[1])
            assert from_bag == from_pcd, (method, k)
            assert sum(from_bag) > 0.3 * len(from_bag)  # a ramp scene: mostly ground
        # The result bag: the same messages plus a `ground` field holding the decisions.
        with rosbag2.Reader(tmp_path / f"bag-{method}" / "ground_bag") as reader:
            for k, (conn, _, raw) in enumerate(reader.messages()):
                msg = store.deserialize_cdr(raw, conn.msgtype)
                ground_field = next(f for f in msg.fields if f.name == "ground")
                cells = msg.data.reshape(msg.height * msg.width, msg.point_step)[:, ground_field.offset]
                assert cells.tobytes() == (tmp_path / f"bag-{method}" / f"frame_{k:06d}.ground").read_bytes()


# --- the Python package -------------------------------------------------------------------------


def test_write_and_read_a_bag_in_python(tmp_path):
    frames = gt.scan("ramp-up", "vlp16-roof", seed=4, frames=3, speed=8.0)
    for layout in ("groundtruth", "velodyne", "ouster"):
        bag = tmp_path / f"bag-{layout}"
        n = gt.write(frames, bag, "mcap", layout=layout)
        assert n == sum(f.shape[0] * f.shape[1] for f in frames)
        back = gt.read(bag)
        assert isinstance(back, list) and len(back) == len(frames)
        for f, b in zip(frames, back):
            assert b.shape == f.shape, layout
            assert b.returns == f.returns, layout
            # The drivers' layouts carry the SemanticKITTI label; ours carries every field.
            assert b.ground_returns == f.ground_returns, layout
        assert len(gt.read(bag / f"bag-{layout}_0.mcap", topic="/roof/points")) == 3


def test_bag_errors_name_what_is_wrong(tmp_path):
    frames = gt.scan("flat", "vlp16-roof", frames=1)
    bag = tmp_path / "bag"
    gt.write(frames, bag, "mcap")
    with pytest.raises(ValueError, match="/nope.*/roof/points"):
        gt.read(bag, topic="/nope")
    mcap = bag / "bag_0.mcap"
    truncated = tmp_path / "truncated.mcap"
    truncated.write_bytes(mcap.read_bytes()[: mcap.stat().st_size // 2])
    with pytest.raises(ValueError, match="truncated.mcap"):
        gt.read(truncated, topic="/roof/points")
    with pytest.raises(ValueError, match="topic"):
        gt.read(tmp_path / "x.pcd", topic="/roof/points")
    with pytest.raises(TypeError, match="Frame"):
        gt.write([1, 2], tmp_path / "bad", "mcap")
