"""A dcfkit tracker as a ``got10k.trackers.Tracker``, for the got10k toolkit's experiments::

    from got10k.experiments import ExperimentDTB70
    from dcfkit.integrations.got10k import Tracker

    ExperimentDTB70("data/DTB70").run(Tracker("strcf"))   # results/DTB70/strcf/<seq>.txt

The boxes got10k writes are the boxes ``dcfkit eval strcf --dataset dtb70`` writes for the
same sequences (to their three decimals), as long as Pillow, which got10k decodes frames
with, and OpenCV, which dcfkit does, return the same pixels (they do for the JPEGs of the
development data: both bundle libjpeg-turbo). What got10k 0.1.3 does, and what this adapter
does about it:

**Images.** ``Tracker.track``, the frame loop of got10k's experiments but VOT's supervised
and real-time runs (``got10k/trackers/__init__.py``), opens each frame with
``PIL.Image.open`` and converts any mode but ``'RGB'`` (grayscale ``'L'``, palette, RGBA)
with ``convert('RGB')``. Those two VOT runs hand over ``Image.open``'s image unconverted,
or with ``read_image=False`` the file's path. dcfkit takes BGR, the order of
``cv2.imread``: the adapter converts a PIL image as ``track`` does and reverses its
channels, reads a path with dcfkit's own :func:`~dcfkit.datasets.read_frame`, and takes a
numpy array in got10k's order: RGB (``(H, W, 3)``) or gray (``(H, W)``). RGB given as BGR
is no error a tracker can see: its gray and Color Names features (STRCF's, among others)
would read other colours.

**Boxes.** The datasets read their annotation files unchanged with ``np.loadtxt``
(``got10k/datasets/otb.py``, ``uav123.py``, ``dtb70.py``, ``tcolor128.py``, ``lasot.py``,
``got10k.py``), so for these benchmarks the box ``init`` receives is **1-based**, the OTB
convention (GOT-10k's annotations are 1-based too, as its authors say in got-10k/toolkit
issue 6). ``ExperimentOTB.run`` (which the DTB70, UAV123, NfS and TColor128 experiments
inherit) writes the boxes ``update`` returns unchanged, ``%.3f``, frame 1 holding the
initial box: the published result files of these benchmarks, and dcfkit's, are 1-based.
Its ``report`` scores them with ``rect_iou`` and ``center_error``
(``got10k/utils/metrics.py``), which only compare the two boxes, so a 1-based box taken
as 0-based is scored without complaint: the tracker learns the target 1 px off in x and y.
The adapter subtracts 1 from x and y of the box ``init`` receives and adds 1 to those
``update`` returns; ``one_based=False`` passes boxes unchanged, for a 0-based dataset.

**Sequences.** got10k calls ``init`` on the same object for each sequence: ``init`` builds
a new dcfkit tracker from the config (read and checked once, when the adapter is made), as
``dcfkit eval`` does per sequence, so nothing learnt on one sequence reaches the next.
dcfkit trackers are deterministic (``is_deterministic=True``: GOT-10k's experiment then runs
one repetition, not three).

Importing this module imports got10k: without it, a :class:`ModuleNotFoundError` names the
extra that installs it (``pip install "dcfkit[got10k]"``).
"""
from __future__ import annotations

import os
from typing import Any, Mapping

import numpy as np
from PIL import Image

from dcfkit.config import load_config
from dcfkit.datasets import read_frame
from dcfkit.errors import DcfkitError, InputError, TrackingError
from dcfkit.running.evaluation import tracker_name
from dcfkit.tracker.tracker import Tracker as DcfTracker

try:
    from got10k.trackers import Tracker as Got10kTracker
except ImportError as exc:  # the toolkit is an optional extra
    raise ModuleNotFoundError(f"dcfkit.integrations.got10k needs the got10k toolkit ({exc}), an optional extra: "
                              f'pip install "dcfkit[got10k]"', name="got10k") from exc

__all__ = ["Tracker", "to_bgr"]

ONE_BASED = np.array([1.0, 1.0, 0.0, 0.0])  # added to (x, y, w, h): 0-based -> 1-based
ONE_BASED.setflags(write=False)  # every adapter's offset


def to_bgr(image: Any, frame: int) -> np.ndarray:
    """A frame as got10k hands it over (a PIL image of any mode, a file path, or an RGB or
    gray array) as dcfkit takes it: ``(H, W, 3)`` uint8 BGR, or the gray array unchanged.
    ``frame`` (1-based) is for the messages."""
    if isinstance(image, (str, os.PathLike)):
        return read_frame(image, f"frame {frame}")
    if isinstance(image, Image.Image):
        image = np.asarray(image if image.mode == "RGB" else image.convert("RGB"))  # as got10k's track()
    elif not isinstance(image, np.ndarray):
        raise InputError(f"frame {frame}: expected a PIL image, an RGB array or an image path, "
                         f"got {type(image).__name__}")
    return np.ascontiguousarray(image[..., ::-1]) if image.ndim == 3 else image


class Tracker(Got10kTracker):
    """A dcfkit config as a got10k tracker: ``init(image, box)``, ``update(image) -> box``.

    ``config`` is what :func:`dcfkit.load_tracker` takes (a shipped name, a path, a dict),
    ``overrides`` its dotted overrides (``{"label.mu": 0.3}``); ``name`` (default: the
    config's) names got10k's result folder. Boxes are got10k's ``(x, y, w, h)``, 1-based
    unless ``one_based=False``. ``dcf`` is the dcfkit tracker of the current sequence (its
    ``last_response``, ``last_confidence``), None before the first ``init``.
    """

    def __init__(self, config: str | os.PathLike | Mapping[str, Any], name: str | None = None,
                 overrides: Mapping[str, Any] | None = None, one_based: bool = True):
        extra = dict(overrides or {})
        if name is not None:
            extra["name"] = name
        self.config = load_config(config, extra)
        super().__init__(tracker_name(self.config), is_deterministic=True)
        self.offset = ONE_BASED if one_based else np.zeros(4)
        self.dcf: DcfTracker | None = None

    def init(self, image: Any, box) -> None:
        """A new sequence: a new dcfkit tracker, initialised on ``box``."""
        self.dcf = None  # a failed init leaves no tracker of the last sequence to update
        dcf = DcfTracker(self.config)
        dcf.init(to_bgr(image, 1), self._zero_based(box))
        self.dcf = dcf

    def update(self, image: Any) -> np.ndarray:
        """The target's box in the next frame, ``(4,) float64`` in got10k's convention."""
        if self.dcf is None:
            raise TrackingError("update() called before init()")
        frame = self.dcf.frame + 1
        try:
            image = to_bgr(image, frame)
        except DcfkitError:
            self.dcf.frame = frame  # counted, as the tracker counts the frames it refuses: numbers stay the video's
            raise
        return np.add(self.dcf.update(image), self.offset)

    def _zero_based(self, box) -> Any:
        try:
            raw = np.asarray(box)
        except ValueError:  # a ragged sequence
            return box
        if raw.dtype.kind not in "iuf" or raw.size != 4:
            return box  # not 4 numbers: dcfkit's init says what it got
        return raw.astype(np.float64).reshape(4) - self.offset
