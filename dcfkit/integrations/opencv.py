"""OpenCV's CSRT, KCF and MOSSE behind the dcfkit tracker protocol, as reference baselines
(``dcfkit eval opencv:CSRT``)."""
from __future__ import annotations

from typing import Any, Callable

import cv2
import numpy as np

from dcfkit.errors import DcfkitError, shown
from dcfkit.opencv_check import contrib_advice

# Preferred constructor first: legacy trackers take and return float boxes (Rect2d).
_OPENCV_CONSTRUCTORS = {
    "CSRT": ("legacy.TrackerCSRT_create", "TrackerCSRT_create"),
    "KCF": ("legacy.TrackerKCF_create", "TrackerKCF_create"),
    "MOSSE": ("legacy.TrackerMOSSE_create",),
}


class OpenCVUnavailable(DcfkitError, LookupError):
    """The requested OpenCV tracker is not in this OpenCV build."""


def _opencv_constructor(name: str):
    for dotted in _OPENCV_CONSTRUCTORS[name]:
        obj = cv2
        for part in dotted.split("."):
            obj = getattr(obj, part, None)
            if obj is None:
                break
        if obj is not None:
            return obj, dotted.startswith("legacy.")
    return None, False


def available_opencv_trackers() -> list[str]:
    """Names of the OpenCV baselines this OpenCV build provides (subset of CSRT, KCF, MOSSE)."""
    return [n for n in _OPENCV_CONSTRUCTORS if _opencv_constructor(n)[0] is not None]


class OpenCVTracker:
    """An OpenCV tracker behind the dcfkit protocol (float ``(x, y, w, h)`` 0-based boxes).

    When OpenCV reports a failure (``ok`` false) the previous box is returned, as the
    tracker keeps no other estimate.
    """

    def __init__(self, name: str):
        self.name = name
        self._tracker = None
        self._box = None

    def init(self, image: np.ndarray, box) -> None:
        create, legacy = _opencv_constructor(self.name)
        self._tracker = create()
        box = np.asarray(box, dtype=np.float64)
        rect = tuple(float(v) for v in box) if legacy else (
            int(round(box[0])), int(round(box[1])), max(1, int(round(box[2]))), max(1, int(round(box[3]))))
        self._tracker.init(image, rect)
        self._box = box.copy()

    def update(self, image: np.ndarray) -> np.ndarray:
        ok, rect = self._tracker.update(image)
        rect = np.asarray(rect, dtype=np.float64)
        if ok and np.isfinite(rect).all() and rect[2] > 0 and rect[3] > 0:
            self._box = rect
        return self._box.copy()


class _OpenCVFactory:
    """Picklable ``make_tracker`` (runs in worker processes with ``jobs > 1``)."""

    def __init__(self, name: str):
        self.name = name

    def __call__(self, config=None) -> OpenCVTracker:
        return OpenCVTracker(self.name)

    def __repr__(self):
        return f"opencv_tracker({self.name!r})"


def opencv_tracker(name: str) -> Callable[[Any], OpenCVTracker]:
    """``make_tracker`` factory for OpenCV's CSRT, KCF or MOSSE (case-insensitive).

    Raises :class:`OpenCVUnavailable` naming the available ones if this build lacks it.
    Use with a config such as ``{"name": "opencv-kcf"}``.
    """
    key = str(name).upper()
    if key not in _OPENCV_CONSTRUCTORS:
        raise OpenCVUnavailable(f"unknown OpenCV tracker {shown(name)}; choose from {', '.join(_OPENCV_CONSTRUCTORS)}")
    if key not in available_opencv_trackers():
        raise OpenCVUnavailable(
            f"OpenCV tracker {key} is not in this OpenCV build (available: "
            f"{', '.join(available_opencv_trackers()) or 'none'}); {contrib_advice(cv2)}")
    return _OpenCVFactory(key)
