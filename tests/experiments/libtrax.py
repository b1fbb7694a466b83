"""ctypes access to the region overlap of a trax C library (by default the ``libtrax.so`` the
vot-trax wheel ships): the reference the reset rules are tested against."""
from __future__ import annotations

import ctypes
import os
from pathlib import Path

LEGACY_RASTERIZATION = 1  # region.h's REGION_LEGACY_RASTERIZATION


class Bounds(ctypes.Structure):
    _fields_ = [("top", ctypes.c_float), ("bottom", ctypes.c_float), ("left", ctypes.c_float),
                ("right", ctypes.c_float)]


class Polygon(ctypes.Structure):
    _fields_ = [("count", ctypes.c_int), ("x", ctypes.POINTER(ctypes.c_float)), ("y", ctypes.POINTER(ctypes.c_float))]


class Container(ctypes.Structure):
    _fields_ = [("type", ctypes.c_int), ("polygon", Polygon)]  # the union's polygon member


class Overlap(ctypes.Structure):
    _fields_ = [("overlap", ctypes.c_float), ("only1", ctypes.c_float), ("only2", ctypes.c_float)]


def library_path() -> Path | None:
    """``$DCFKIT_TRAX_LIBRARY`` if set, else the vot-trax wheel's ``libtrax.so``, or None."""
    if os.environ.get("DCFKIT_TRAX_LIBRARY"):
        return Path(os.environ["DCFKIT_TRAX_LIBRARY"])
    try:
        import trax
    except ImportError:
        return None
    found = Path(trax.__file__).parent / "libtrax.so"
    return found if found.is_file() else None


class Trax:
    """``rectangles(box, gt, bounds)``: the overlap of two rectangle regions, as the trax client
    tests a failure; ``polygons(box, gt, bounds)``: of two four-corner polygons ``x .. x + w``,
    as the VOT2016 MATLAB toolkit's ``region_overlap`` builds them. ``bounds``: ``(left, top,
    right, bottom)`` or None."""

    def __init__(self, path: Path, legacy: bool = False):
        lib = self.lib = ctypes.CDLL(str(path))
        lib.region_create_rectangle.restype = ctypes.POINTER(Container)
        lib.region_create_rectangle.argtypes = [ctypes.c_float] * 4
        lib.region_create_polygon.restype = ctypes.POINTER(Container)
        lib.region_create_polygon.argtypes = [ctypes.c_int]
        lib.region_compute_overlap.restype = Overlap
        lib.region_compute_overlap.argtypes = [ctypes.POINTER(Container), ctypes.POINTER(Container), Bounds]
        lib.region_release.argtypes = [ctypes.POINTER(ctypes.POINTER(Container))]
        (lib.region_set_flags if legacy else lib.region_clear_flags)(LEGACY_RASTERIZATION)

    def _overlap(self, a, b, bounds) -> float:
        big = 3.4028234663852886e38  # FLT_MAX: region_no_bounds
        left, top, right, bottom = bounds if bounds is not None else (-big, -big, big, big)
        found = self.lib.region_compute_overlap(a, b, Bounds(top, bottom, left, right)).overlap
        for region in (a, b):
            self.lib.region_release(ctypes.byref(region))
        return float(found)

    def rectangles(self, box, gt, bounds=None) -> float:
        return self._overlap(self.lib.region_create_rectangle(*map(float, box)),
                             self.lib.region_create_rectangle(*map(float, gt)), bounds)

    def _polygon(self, box):
        x, y, w, h = (float(v) for v in box)
        region = self.lib.region_create_polygon(4)
        for k, (px, py) in enumerate(((x, y), (x + w, y), (x + w, y + h), (x, y + h))):
            region.contents.polygon.x[k], region.contents.polygon.y[k] = px, py
        return region

    def polygons(self, box, gt, bounds=None) -> float:
        return self._overlap(self._polygon(box), self._polygon(gt), bounds)
