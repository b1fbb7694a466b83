"""The rasterised overlaps of two toolkits of VOT's reset-based experiment, for boxes ``(N, 4)``
``x, y, w, h`` (0-based, float64): both count the pixels of rectangles whose corners are rounded,
as the toolkits do (docs/evaluation.md, "Reset-based experiment"); the boxes must be finite with
a positive width and height (:func:`dcfkit.experiments.vot.valid_box`).

* :func:`trax2016_overlap`: the region overlap of the trax library of 2016 (``region.c``,
  June 2016 to May 2017, not its legacy rasterisation), which the VOT2016 MATLAB toolkit used.
  Its arithmetic is float32 as the library's; a rectangle whose rounded corners coincide in x or
  y has no pixel (its scanline finds no span), and two such rectangles' overlap is NaN (0 / 0).
* :func:`vottoolkit_overlap`: vot-toolkit 0.9 (Python): ``x, y, w, h`` rounded half to even,
  pixels ``x .. x + w - 1``; two boxes whose bounding union is one pixel wide or high overlap 1.
"""
from __future__ import annotations

import numpy as np

__all__ = ["NO_BOUNDS", "trax2016_overlap", "vottoolkit_overlap"]

_F = np.float32
NO_BOUNDS = (-np.finfo(_F).max, -np.finfo(_F).max, np.finfo(_F).max, np.finfo(_F).max)  # the library's region_no_bounds


def _c_round(v: np.ndarray) -> np.ndarray:
    """C's ``round``: halves away from zero (numpy's rounds them to even)."""
    return (np.sign(v) * np.floor(np.abs(v.astype(np.float64)) + 0.5)).astype(_F)


def _corners(boxes: np.ndarray, inclusive: bool) -> tuple[np.ndarray, ...]:
    """``(x0, y0, x1, y1)`` float32 of the polygon the toolkit makes of each box: a rectangle
    region converted in float32 to ``x .. x + w - 1`` (``inclusive``: the trax client's failure
    test), or the MATLAB toolkit's own polygon ``x .. x + w`` summed in float64 (its analysis)."""
    b = np.asarray(boxes, dtype=np.float64).reshape(-1, 4)
    if inclusive:
        x, y, w, h = (b[:, k].astype(_F) for k in range(4))
        return x, y, (x + w) - _F(1), (y + h) - _F(1)
    return b[:, 0].astype(_F), b[:, 1].astype(_F), (b[:, 0] + b[:, 2]).astype(_F), (b[:, 1] + b[:, 3]).astype(_F)


def _window_bounds(c, bounds) -> tuple[np.ndarray, ...]:
    """Each polygon's bounds rounded outward (floor, ceil) and cut to ``bounds``."""
    x0, y0, x1, y1 = c
    left, top, right, bottom = (_F(v) for v in bounds)
    return (np.maximum(np.floor(np.minimum(x0, x1)), left), np.maximum(np.floor(np.minimum(y0, y1)), top),
            np.minimum(np.ceil(np.maximum(x0, x1)), right), np.minimum(np.ceil(np.maximum(y0, y1)), bottom))


def _span(a: np.ndarray, b: np.ndarray, origin: np.ndarray, size: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``[lo, hi]`` (inclusive; empty when lo > hi) of the pixels a scanline fills between the
    edges at ``a`` and ``b`` in a window ``size`` wide from ``origin``: both rounded after the
    offset, none when they coincide, cut to the window."""
    ra, rb = _c_round(a - origin), _c_round(b - origin)
    lo, hi = np.minimum(ra, rb).astype(np.int64), np.maximum(ra, rb).astype(np.int64)
    empty = (lo == hi) | (lo >= size) | (hi < 0)
    lo, hi = np.maximum(lo, 0), np.minimum(hi, size - 1)
    return np.where(empty, 1, lo), np.where(empty, 0, hi)


def _count(lo1, hi1, lo2, hi2) -> np.ndarray:
    return np.maximum(0, np.minimum(hi1, hi2) - np.maximum(lo1, lo2) + 1)


def trax2016_overlap(boxes, gts, bounds=NO_BOUNDS, inclusive: bool = False) -> np.ndarray:
    """Overlaps ``(N,)`` float64 (float32 values) of ``boxes`` and ``gts`` as trax 2016's
    ``region_compute_overlap`` gives them inside ``bounds`` ``(left, top, right, bottom)``:
    0 when either rectangle's window has no area or the windows do not overlap, else
    intersection over union of the pixels (NaN when neither has one). ``inclusive``: the
    corners of a converted rectangle region (:func:`_corners`)."""
    c1, c2 = _corners(boxes, inclusive), _corners(gts, inclusive)
    (l1, t1, r1, b1), (l2, t2, r2, b2) = _window_bounds(c1, bounds), _window_bounds(c2, bounds)
    ox, oy = np.minimum(l1, l2), np.minimum(t1, t2)
    width = np.trunc(np.maximum(r1, r2) - ox).astype(np.int64) + 1
    height = np.trunc(np.maximum(b1, b2) - oy).astype(np.int64) + 1
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        a1, a2 = ((r1 - l1) * (b1 - t1)).astype(np.float64), ((r2 - l2) * (b2 - t2)).astype(np.float64)
        degenerate = (a1 / a2 < 1e-10) | (a2 / a1 < 1e-10) | (width < 1) | (height < 1)
        inter = (np.minimum(r1, r2) - np.maximum(l1, l2)) * (np.minimum(b1, b2) - np.maximum(t1, t2))
        ratio = inter / ((r1 - l1) * (b1 - t1) + (r2 - l2) * (b2 - t2) - inter)
        apart = np.where(ratio < 0, _F(0), ratio) == 0
        xs1, xs2 = _span(c1[0], c1[2], ox, width), _span(c2[0], c2[2], ox, width)
        ys1, ys2 = _span(c1[1], c1[3], oy, height), _span(c2[1], c2[3], oy, height)
        both = _count(*xs1, *xs2) * _count(*ys1, *ys2)
        union = _count(*xs1, *xs1) * _count(*ys1, *ys1) + _count(*xs2, *xs2) * _count(*ys2, *ys2) - both
        found = both.astype(_F) / union.astype(_F)
    return np.where(degenerate | apart, 0.0, found.astype(np.float64))


def vottoolkit_overlap(boxes, gts, size: tuple[int, int]) -> np.ndarray:
    """Overlaps ``(N,)`` float64 of ``boxes`` and ``gts`` as vot-toolkit 0.9's
    ``calculate_overlap`` of two rectangles inside an image ``size`` ``(width, height)`` (its
    experiments and analyses bound every overlap so): pixels ``x .. x + w - 1`` of the boxes stored
    in float32 and rounded (half to even); 1 when the union of their bounds is at most one pixel
    wide or high, 0 when its part inside the image is."""
    a, b = (np.round(np.asarray(v, dtype=np.float64).reshape(-1, 4).astype(_F)).astype(np.float64)
            for v in (boxes, gts))
    ends_a, ends_b = a[:, :2] + a[:, 2:] - 1, b[:, :2] + b[:, 2:] - 1
    low, high = np.minimum(a[:, :2], b[:, :2]), np.maximum(ends_a, ends_b)
    one = (low >= high).any(axis=1)
    low, high = np.maximum(low, 0), np.minimum(high, np.asarray(size, dtype=np.float64) - 1)
    outside = (low >= high).any(axis=1)

    def pixels(start, end):  # (N, 2) first and last pixel of each axis inside [low, high]
        inside = ~((start > high) | (end < low)).any(axis=1, keepdims=True)
        return np.where(inside, np.maximum(start, low), 1.0), np.where(inside, np.minimum(end, high), 0.0)

    (sa, ea), (sb, eb) = pixels(a[:, :2], ends_a), pixels(b[:, :2], ends_b)
    area = lambda s, e: np.prod(np.maximum(0.0, e - s + 1), axis=1)  # noqa: E731
    both = area(np.maximum(sa, sb), np.minimum(ea, eb))
    union = area(sa, ea) + area(sb, eb) - both
    with np.errstate(invalid="ignore", divide="ignore"):
        found = np.where(union > 0, both / np.maximum(union, 1), 0.0)
    return np.where(one, 1.0, np.where(outside, 0.0, found))
