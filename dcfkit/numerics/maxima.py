"""Maxima of response maps: local maxima of a circular map (dcfkit's distractors), and MATLAB's
``imregionalmax`` and ``bwconncomp`` on plain ones (the authors' distractors, CSR-DCF's channel
reliability). OpenCV's morphology, because ``scipy.ndimage`` costs 0.3 s of import; it is
imported only where connected components are needed."""
from __future__ import annotations

import cv2
import numpy as np

_KERNEL = np.ones((3, 3), np.uint8)


def local_maxima(r: np.ndarray, size: int = 3) -> tuple[np.ndarray, np.ndarray]:
    """Local maxima of a circular (H, W) map: rows, cols of pixels equal to the max of their
    ``size`` x ``size`` (odd; wrapped) neighbourhood and strictly above its minimum (no plateaus
    of a flat map). Sorted by value, highest first."""
    if size < 1 or size % 2 == 0:
        raise ValueError(f"local_maxima: size must be odd and positive, got {size}")
    half = size // 2
    padded = np.pad(r, half, mode="wrap")
    kernel = np.ones((size, size), np.uint8)
    inner = (slice(half, half + r.shape[0]), slice(half, half + r.shape[1]))
    filtered = cv2.dilate(padded, kernel)[inner]
    lowest = cv2.erode(padded, kernel)[inner]
    rows, cols = np.nonzero((r == filtered) & (r > lowest))
    order = np.argsort(-r[rows, cols], kind="stable")
    return rows[order], cols[order]


def regional_maxima(maps: np.ndarray) -> np.ndarray:
    """MATLAB's ``imregionalmax`` (8-connected, the map not wrapped) of an (H, W) map or of each
    map of a (C, H, W) stack: the pixels of every connected plateau whose neighbours outside it
    are all lower. Boolean, the shape of ``maps``. float32 and float64 maps keep their values
    (others are read as float64); the maps must be free of NaN, which has no order."""
    top, leaks = _tops(maps)
    if leaks.any():
        labels, _ = components(top)
        top &= ~np.isin(labels, labels[leaks])
    return np.moveaxis(top, -1, 0) if top.ndim == 3 else top


def maxima_components(maps: np.ndarray) -> tuple[np.ndarray, int]:
    """The plateaus of :func:`regional_maxima`, each map's apart (``bwconncomp`` of each):
    labels 1 to count, 0 elsewhere, the shape of ``maps``, and the count."""
    top, leaks = _tops(maps)
    labels, count = components(top)
    if leaks.any():  # renumber the plateaus that are maxima
        keep = np.ones(count + 1, bool)
        keep[0] = False
        keep[labels[leaks]] = False
        number = np.zeros(count + 1, labels.dtype)
        count = int(keep.sum())
        number[keep] = np.arange(1, count + 1)
        labels = number[labels]
    return (np.moveaxis(labels, -1, 0) if labels.ndim == 3 else labels), count


def _tops(maps: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(H, W) or (H, W, C) (a stack's maps last, for OpenCV): the pixels with no higher
    neighbour, and those of them beside an equal pixel that has one (their plateau is none)."""
    maps = np.asarray(maps)
    r = maps if maps.dtype in (np.float32, np.float64) else maps.astype(np.float64)
    r = np.ascontiguousarray(np.moveaxis(r, 0, -1) if r.ndim == 3 else r)
    # OpenCV pads a dilation with the lowest finite value, which no border pixel is below but
    # -inf (and a plateau of -inf is a maximum only where the whole map is -inf, as MATLAB's);
    # it returns one channel's (H, W, 1) as (H, W)
    top = r >= cv2.dilate(r, _KERNEL).reshape(r.shape)
    beside = cv2.dilate(np.where(top, -np.inf, r).astype(r.dtype, copy=False), _KERNEL).reshape(r.shape)
    return top, top & (beside == r)


def components(mask: np.ndarray) -> tuple[np.ndarray, int]:
    """MATLAB's ``bwconncomp`` (8-connected) of a boolean (H, W) map, or of each (H, W) plane of
    an (H, W, C) stack apart: integer labels (0 off the mask) and their count."""
    import scipy.ndimage  # deferred: 0.3 s of import

    if mask.ndim == 2:
        return scipy.ndimage.label(mask, structure=np.ones((3, 3), bool))
    structure = np.zeros((3, 3, 3), bool)
    structure[:, :, 1] = True  # never across planes
    return scipy.ndimage.label(mask, structure=structure)
