"""LiDAR ground truth on demand: scans as numpy arrays, regions and scores for any segmenter.

Everything here is the Rust code of this repository (crates ``groundtruth-scenario``, ``sim``,
``classifier``) behind PyO3::

    import groundtruth as gt

    frame, = gt.scan("ramp", "hdl64e-roof", params={"slope_deg": -12.0, "distance_m": 5.0},
                     mount={"z_m": 1.9})
    points, cells = frame.points()              # (N, 4) float32 x y z intensity, cell indices
    mine = abs(points[:, 2]) < 0.25             # any segmenter: one bool per point
    s = gt.score(frame, mine, region="ramp-surface")
    assert s.recall < 0.95, s                   # a flat world loses the ramp
    ours = gt.score(frame, gt.classify(frame, "nitsch"), region="ramp-surface")
    assert ours.recall >= 0.95, ours
"""

from ._native import (
    FAMILIES,
    METHODS,
    REGIONS,
    RIGS,
    SCENES,
    WRITE_FORMATS,
    Frame,
    Score,
    __version__,
    classify,
    eval_dataset,
    read,
    regions,
    scan,
    score,
    write,
)

__all__ = [
    "FAMILIES",
    "METHODS",
    "REGIONS",
    "RIGS",
    "SCENES",
    "WRITE_FORMATS",
    "Frame",
    "Score",
    "__version__",
    "classify",
    "eval_dataset",
    "read",
    "regions",
    "scan",
    "score",
    "write",
]
