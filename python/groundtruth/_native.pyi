"""Type stubs of the native module ``groundtruth._native`` (re-exported by ``groundtruth``)."""

from os import PathLike
from typing import Any, Mapping, Optional, Sequence, Union, final, overload

import numpy as np
import numpy.typing as npt

__all__ = [
    "__version__",
    "SCENES",
    "FAMILIES",
    "RIGS",
    "METHODS",
    "REGIONS",
    "WRITE_FORMATS",
    "Frame",
    "Score",
    "scan",
    "score",
    "regions",
    "classify",
    "eval_dataset",
    "read",
    "write",
    "_time_rust_scan",
]
__version__: str
SCENES: list[str]
"""Bundled scene names (``flat``, ``ramp-up``, ``basin``, ``city``, ...)."""
FAMILIES: list[str]
"""Scene generator families (``flat``, ``ramp``, ``basin``, ``elevated``, ``hill``, ...)."""
RIGS: list[str]
"""Rig presets (``vlp16-roof``, ``hdl64e-roof``, ``os1-64-roof``, ``os1-128-roof``, ``lux``, ...)."""
METHODS: list[str]
"""Our classification methods (``nitsch``, ``ransac``, ``grid``, ``mcdaniel``, ...)."""
REGIONS: list[str]
"""Region names; also ``class:<name or id>``, ``instance:<id>``, ``range:<min>-<max>``."""
WRITE_FORMATS: list[str]
"""Formats ``write`` takes: ``pcd``, ``pcd-ascii``, ``ply``, ``kitti``, ``las``."""

_Path = Union[str, "PathLike[str]"]
_ParamValue = Union[float, int, bool, str]

@final
class Frame:
    """One frame of a scan (or a file read back): the labelled ordered cloud as numpy arrays.

    Arrays have the grid shape ``(planes * rows, cols)`` (row 0 = lowest beam, column 0 = left-most
    azimuth; echo plane k occupies rows ``k * rows .. (k + 1) * rows``). Each access returns a fresh
    copy of the Rust field.
    """

    @property
    def rows(self) -> int:
        """Grid rows per echo plane."""
    @property
    def cols(self) -> int:
        """Grid columns."""
    @property
    def planes(self) -> int:
        """Echo planes (1 except multi-echo sensors)."""
    @property
    def shape(self) -> tuple[int, int]:
        """``(planes * rows, cols)``."""
    @property
    def index(self) -> int:
        """Frame index within its scan."""
    @property
    def scene(self) -> str:
        """Scene name (or the file read)."""
    @property
    def family(self) -> str:
        """Scene generator family (``"unknown"`` for a file)."""
    @property
    def rig(self) -> str:
        """Rig name (empty for a file)."""
    @property
    def seed(self) -> int:
        """The scan's seed."""
    @property
    def returns(self) -> int:
        """Cells holding a return."""
    @property
    def ground_returns(self) -> int:
        """Returns whose ground truth is ground."""
    @property
    def world_from_vehicle(self) -> npt.NDArray[np.float32]:
        """Vehicle pose at the frame's start, 4 x 4."""
    def vehicle_from_sensor(self, sensor: int = 0) -> npt.NDArray[np.float32]:
        """The rig's sensor mount, 4 x 4 (vehicle from sensor); ``ValueError`` for a file read back."""
    @property
    def xyz(self) -> npt.NDArray[np.float32]:
        """``(H, W, 3)`` vehicle-frame positions, metres; NaN where no return."""
    @property
    def normal(self) -> npt.NDArray[np.float32]:
        """``(H, W, 3)`` true unit surface normals; zero where no return."""
    @property
    def range(self) -> npt.NDArray[np.float32]:
        """``(H, W)`` range from the beam origin, metres; NaN where no return."""
    @property
    def intensity(self) -> npt.NDArray[np.float32]:
        """``(H, W)`` intensity in [0, 1]."""
    @property
    def time(self) -> npt.NDArray[np.float64]:
        """``(H, W)`` shot time, seconds since the start of the scan."""
    @property
    def ring(self) -> npt.NDArray[np.uint16]:
        """``(H, W)`` the sensor's ring index."""
    @property
    def column(self) -> npt.NDArray[np.uint32]:
        """``(H, W)`` the sensor's column index."""
    @property
    def sensor(self) -> npt.NDArray[np.uint8]:
        """``(H, W)`` sensor id; 255 where no sensor covers the cell."""
    @property
    def echo(self) -> npt.NDArray[np.uint8]:
        """``(H, W)`` echo number (0 = first)."""
    @property
    def label(self) -> npt.NDArray[np.uint16]:
        """``(H, W)`` SemanticKITTI class id (bush: 73)."""
    @property
    def instance(self) -> npt.NDArray[np.uint32]:
        """``(H, W)`` instance id (0 = stuff)."""
    @property
    def ground(self) -> npt.NDArray[np.bool_]:
        """``(H, W)`` ground truth."""
    @property
    def valid(self) -> npt.NDArray[np.bool_]:
        """``(H, W)`` whether the cell holds a return."""
    def points(self) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.int64]]:
        """The returns as ``(N, 4)`` ``x y z intensity`` (vehicle frame) in grid order, and their flat
        cell indices: ``frame.xyz.reshape(-1, 3)[cells] == points[:, :3]``."""
    @property
    def ordering(self) -> Optional[dict[str, Any]]:
        """How ``read()`` ordered the frame (``summary``: the line ``groundtruth classify`` prints;
        ``sensor``: the catalogue's sensor matched (``model``) or None where one was given; ``path``,
        the counts, ``rows``, ``cols``, ``planes``, ``file``, ``layout``, ``layout_by``, ...); None
        for scans and frames read with ``ordered=False``."""
    @property
    def cell_of_point(self) -> Optional[npt.NDArray[np.int64]]:
        """The flat cell of each point of the file read, in the file's order (-1: skipped); None
        where the frame was not reordered."""
    def decisions_per_point(self, decisions: npt.NDArray[np.bool_]) -> npt.NDArray[np.uint8]:
        """``(H, W)`` decisions as one uint8 per point of the file read, in its own order (1 =
        ground): the bytes of ``groundtruth classify``'s ``.ground`` file."""
    def region(self, name: str) -> npt.NDArray[np.bool_]:
        """The ``(H, W)`` mask of region ``name``; ``ValueError`` for a region of another family."""
    def regions(self) -> dict[str, npt.NDArray[np.bool_]]:
        """Every region this frame's scene has, name -> mask."""

@final
class Score:
    """Ground decisions over a region: counts (ground is positive) and rates (NaN on a zero
    denominator)."""

    @property
    def region(self) -> str: ...
    @property
    def tp(self) -> int:
        """Ground returns called ground."""
    @property
    def fp(self) -> int:
        """Non-ground returns called ground."""
    @property
    def tn(self) -> int:
        """Non-ground returns called non-ground."""
    @property
    def fn(self) -> int:
        """Ground returns called non-ground."""
    @property
    def returns(self) -> int: ...
    @property
    def ground(self) -> int: ...
    @property
    def accuracy(self) -> float: ...
    @property
    def fpr(self) -> float:
        """False-ground rate ``fp / (fp + tn)``."""
    @property
    def false_ground_rate(self) -> float: ...
    @property
    def precision(self) -> float: ...
    @property
    def recall(self) -> float: ...
    @property
    def f1(self) -> float: ...
    @property
    def iou(self) -> float: ...
    def as_dict(self) -> dict[str, Union[str, int, float]]: ...

def scan(
    scene: str,
    rig: str,
    *,
    params: Optional[Mapping[str, _ParamValue]] = None,
    mount: Optional[Mapping[str, Union[float, int]]] = None,
    seed: int = 0,
    frames: int = 1,
    speed_m_per_s: float = 0.0,
    yaw_rate_deg_per_s: float = 0.0,
    waypoints_m: Optional[Sequence[tuple[float, float]]] = None,
    ideal: bool = False,
    noise_scale: Optional[float] = None,
    dropout: Optional[float] = None,
    intensity_scale: Optional[float] = None,
    weather: Optional[str] = None,
) -> list[Frame]:
    """Scan ``scene`` (bundled name, built-in such as ``flat-objects``, family, ``.toml`` path or
    TOML text) with ``rig`` (preset, ``.toml`` path or TOML text). The keywords are a scan spec's
    fields (docs/scan-spec.md) with its ranges and messages. ``params``: family parameters;
    ``mount``: ``x_m y_m z_m roll_deg pitch_deg yaw_deg``, ``sensor`` (index, name or ``"rig"``) and
    ``mode`` (``"absolute"``/``"relative"``); ``speed`` is the deprecated spelling of
    ``speed_m_per_s``; ``ideal``: exact ranges; ``weather``:
    ``"fog:visibility_m=50"``, ``"rain:rate_mm_h=10"``, ``"snow:rate_mm_h=2"`` or ``"clear"``
    (returns from the medium get labels 150 fog, 151 rain, 152 snow). Deterministic."""

def regions(frame: Frame) -> dict[str, npt.NDArray[np.bool_]]:
    """Every region of the frame's scene, name -> ``(H, W)`` mask."""

@overload
def score(frame: Frame, decisions: npt.NDArray[np.bool_], region: Optional[str] = None) -> Score:
    """Score bool ``decisions`` (grid ``(H, W)``, ``H * W`` cells, or one per return in ``points()``
    order) over ``region`` (default: every return)."""
@overload
def score(
    frame: Sequence[Frame], decisions: Sequence[npt.NDArray[np.bool_]], region: Optional[str] = None
) -> Score:
    """Pooled over all the frames of one scan (in order), one decision array per frame."""

@overload
def classify(frame: Frame, method: str = "nitsch", model: Optional[_Path] = None) -> npt.NDArray[np.bool_]:
    """Our method ``method`` on the frame: ``(H, W)`` decisions, True = ground."""
@overload
def classify(
    frame: Sequence[Frame], method: str = "nitsch", model: Optional[_Path] = None
) -> list[npt.NDArray[np.bool_]]:
    """One method instance over the frames in order (``grid`` accumulates its map)."""

def eval_dataset(
    path: _Path,
    methods: Sequence[str] = ...,
    *,
    rig: Optional[str] = None,
    calibration: Optional[_Path] = None,
    protocol: str = "semantickitti",
    ground: Optional[Sequence[int]] = None,
    ignore: Optional[Sequence[int]] = None,
    sensor_height_m: float = 1.73,
    sequences: Optional[Sequence[str]] = None,
    max_frames: Optional[int] = None,
    model: Optional[_Path] = None,
    layout: Optional[str] = None,
) -> dict[str, Any]:
    """Score our methods (default ``nitsch`` and ``learned``) on a labelled SemanticKITTI-layout
    recording or a nuScenes-lidarseg folder (``lidar/*.pcd.bin``, ``lidarseg/*_lidarseg.bin``), as
    ``groundtruth eval --dataset`` does; the dict is its ``--json`` document:
    ``result["methods"]["learned"]["pooled"]["f1"]``, per frame under ``"frames"``. ``layout``
    (``"kitti"``, ``"nuscenes"``) names the records of the ``.bin`` files; ``ground`` replaces the
    protocol's ground class ids and ``ignore`` leaves more classes out (WADS's snowfall:
    ``ground=[40, 44, 48, 49, 60, 72, 111], ignore=[110]``)."""

def read(
    path: _Path,
    topic: Optional[str] = None,
    layout: Optional[str] = None,
    rig: Optional[str] = None,
    calibration: Optional[_Path] = None,
    ordered: bool = True,
) -> Union[Frame, list[Frame]]:
    """Read a ``.pcd``, ``.ply``, ``.las``, KITTI ``.bin`` (+ ``.label``) or nuScenes ``.pcd.bin`` into
    a Frame, ordered into rings and columns as ``groundtruth classify`` orders it (``ordered=True``):
    a ring-less ``.bin`` or an unorganized cloud gets its rings and columns recovered (the sensor
    matched against the catalogue, or an unnamed sensor), from its ring field, or from ``rig`` (a
    single-sensor rig, as ``--rig``) or ``calibration`` (the sensor's calibration file, as
    ``--calibration``); ``Frame.ordering`` says how. ``ValueError`` (naming the argument) where no
    order can be recovered. ``ordered=False`` reads it as stored (unorganized files give a
    ``(1, N)`` grid in file order). ``layout`` (``"kitti"``, ``"nuscenes"``) names the records of a
    ``.bin`` (default: by name and content). A ROS 2 bag (``.mcap`` or a rosbag2 directory) gives a
    list of Frames, one per PointCloud2 message of ``topic``."""

def write(
    frame: Union[Frame, Sequence[Frame]], path: _Path, format: Optional[str] = None, layout: str = "groundtruth"
) -> int:
    """Write the frame as ``pcd``, ``pcd-ascii``, ``ply``, ``kitti`` (``.bin`` + ``.label``
    [+ ``.calib.txt``]), ``las``, or ``mcap`` (a ROS 2 bag directory of one frame or a list of
    frames); ``layout`` (``groundtruth``, ``velodyne``, ``ouster``) for PCD and bags; returns the
    points written."""

def _time_rust_scan(scene: str, rig: str, repeats: int = 5, ideal: bool = False) -> list[float]:
    """Benchmark helper: seconds of ``repeats`` scans through the Rust API alone."""
