"""The scenarios of the test suite as a table: Patchwork++ (this directory's `segmenter.py`) next to
our `nitsch`, seed 0, HDL-64E on the roof. Prints Markdown.

    python examples/python/report.py
"""

import groundtruth as gt
from segmenter import segment

RIG = "hdl64e-roof"
# (what, scene, scan arguments, region, rate): the same scenes and regions as the tests.
ROWS = [
    ("12 deg up ramp", "ramp-up", {}, "ramp-surface", "recall"),
    ("8 deg down ramp 8 m ahead", "ramp", {"params": {"slope_deg": -8.0, "distance_m": 8.0}}, "ramp-surface", "recall"),
    (
        "12 deg down ramp 5 m ahead, sensor at 1.9 m",
        "ramp",
        {"params": {"slope_deg": -12.0, "distance_m": 5.0}, "mount": {"z_m": 1.9}},
        "ramp-surface",
        "recall",
    ),
    ("objects beside the up ramp", "ramp-up", {}, "non-ground", "fpr"),
    ("ground beyond a basin", "basin", {}, "beyond-basin", "recall"),
    ("basin floor", "basin", {}, "basin-floor", "recall"),
    ("hill slope", "hill", {}, "hill-slope", "recall"),
    ("vehicle roofs", "elevated", {}, "vehicle-roofs", "fpr"),
    ("flat raised tops (docks, platforms, roofs)", "elevated", {}, "flat-raised-tops", "fpr"),
    ("0.8 m plateaus (raised ground)", "elevated", {"params": {"plateau_height_m": 0.8}}, "plateau", "recall"),
]


def main():
    print("| scenario | region | returns | rate | Patchwork++ | nitsch |")
    print("|---|---|---|---|---|---|")
    for what, scene, args, region, rate in ROWS:
        (frame,) = gt.scan(scene, RIG, **args)
        pw = gt.score(frame, segment(frame), region=region)
        ours = gt.score(frame, gt.classify(frame, "nitsch"), region=region)
        name = "recall" if rate == "recall" else "false-ground rate"
        print(f"| {what} | `{region}` | {pw.returns} | {name} | {getattr(pw, rate):.3f} | {getattr(ours, rate):.3f} |")


if __name__ == "__main__":
    main()
