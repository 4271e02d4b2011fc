"""The segmenter under test: Patchwork++ (PyPI `pypatchworkpp`), adapted to `groundtruth` frames.

Replace `segment()` with your own: it gets one frame and returns one bool per return (in
`frame.points()` order), True = ground.
"""

import contextlib
import os

import numpy as np
import pypatchworkpp


@contextlib.contextmanager
def _quiet_stdout():
    """Patchwork++ prints a line from C++ on construction; keep pytest's output clean."""
    fd = os.dup(1)
    try:
        with open(os.devnull, "w") as null:
            os.dup2(null.fileno(), 1)
            yield
    finally:
        os.dup2(fd, 1)
        os.close(fd)


def segment(frame) -> np.ndarray:
    """Patchwork++ with its default parameters (tuned for KITTI's HDL-64E) on the frame's returns,
    given in the sensor frame as a real driver delivers them, with the rig's mount height as
    `sensor_height`."""
    vehicle_from_sensor = frame.vehicle_from_sensor()
    points, _cells = frame.points()  # (N, 4) x y z intensity, vehicle frame
    xyz1 = np.c_[points[:, :3], np.ones(len(points), dtype=np.float32)]
    in_sensor = (np.linalg.inv(vehicle_from_sensor) @ xyz1.T).T[:, :3]
    params = pypatchworkpp.Parameters()
    params.verbose = False
    params.sensor_height = float(vehicle_from_sensor[2, 3])
    with _quiet_stdout():
        pw = pypatchworkpp.patchworkpp(params)
    pw.estimateGround(np.c_[in_sensor, points[:, 3]].astype(np.float64))
    ground = np.zeros(len(points), dtype=bool)
    ground[pw.getGroundIndices()] = True
    return ground
