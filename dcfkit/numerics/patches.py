"""Image patches: crop a region around a centre (edges replicated) and resize it.

Coordinates are 0-based pixel indices, (y, x) order for centres and (h, w) for sizes; a box
(x, y, w, h) covering pixels x..x+w-1 has its centre at x + (w - 1) / 2.
"""
from __future__ import annotations

from typing import Callable

import cv2
import numpy as np

from dcfkit.numerics.imresize import imresize

from dcfkit.errors import InputError
from dcfkit.limits import IMAGE_PIXELS_VARIABLE, max_image_pixels


def box_to_centre_size(box) -> tuple[np.ndarray, np.ndarray]:
    """(x, y, w, h) -> centre (y, x) and size (h, w), float64."""
    x, y, w, h = (float(v) for v in box)
    return np.array([y + (h - 1) / 2, x + (w - 1) / 2]), np.array([h, w])


def centre_size_to_box(centre, size) -> tuple[float, float, float, float]:
    """Inverse of :func:`box_to_centre_size`."""
    (cy, cx), (h, w) = centre, size
    return (float(cx - (w - 1) / 2), float(cy - (h - 1) / 2), float(w), float(h))


def _origin(centre: float, size: int) -> int:
    """First pixel of ``size`` whole pixels centred on ``centre``."""
    return int(np.floor(centre - (size - 1) / 2 + 0.5))


def crop(image: np.ndarray, centre, region) -> np.ndarray:
    """The ``region`` (h, w) pixels around ``centre`` (y, x); outside pixels replicate the edge."""
    return cropper(image.shape, centre, region)(image)


def cropper(shape, centre, region) -> Callable[[np.ndarray], np.ndarray]:
    """:func:`crop` with its geometry worked out once, for images of ``shape`` (H, W[, C])."""
    rh, rw = max(int(round(region[0])), 1), max(int(round(region[1])), 1)
    return _cropper_at(shape, _origin(centre[0], rh), _origin(centre[1], rw), rh, rw)


def pixel_cropper(shape, y0: int, x0: int, rh: int, rw: int) -> Callable[[np.ndarray], np.ndarray]:
    """Rows y0..y0+rh-1 and columns x0..x0+rw-1 (0-based) of images of ``shape``, outside
    pixels replicating the edge (for crops whose first pixel a caller decides, as ECO's)."""
    return _cropper_at(shape, y0, x0, rh, rw)


def _cropper_at(shape, y0: int, x0: int, rh: int, rw: int) -> Callable[[np.ndarray], np.ndarray]:
    """Rows y0..y0+rh-1 and columns x0..x0+rw-1, outside pixels replicating the edge."""
    height, width = shape[:2]
    if y0 >= 0 and x0 >= 0 and y0 + rh <= height and x0 + rw <= width:
        return lambda image: image[y0:y0 + rh, x0:x0 + rw]
    _check_copy(rh, rw, width, height)  # checked here, where the geometry is built: before any copy
    # the part inside the image (at least its nearest edge pixel), then replicate its borders
    ya, xa = min(max(y0, 0), height - 1), min(max(x0, 0), width - 1)
    yb, xb = max(min(y0 + rh, height), ya + 1), max(min(x0 + rw, width), xa + 1)
    top, left = max(ya - y0, 0), max(xa - x0, 0)
    bottom, right = rh - top - (yb - ya), rw - left - (xb - xa)
    if min(top, bottom, left, right) < 0:  # region entirely beyond one edge: rows/cols replicate it
        rows = np.clip(np.arange(y0, y0 + rh), 0, height - 1)[:, None]
        cols = np.clip(np.arange(x0, x0 + rw), 0, width - 1)[None, :]
        return lambda image: image[rows, cols]
    return lambda image: cv2.copyMakeBorder(image[ya:yb, xa:xb], top, bottom, left, right, cv2.BORDER_REPLICATE)


def _check_copy(rh: int, rw: int, width: int, height: int) -> None:
    """InputError if a ``rw`` x ``rh`` copy (a region partly outside the image, its edges
    replicated) would hold more than :func:`max_image_pixels`."""
    limit = max_image_pixels()
    if rh * rw > limit:
        raise InputError(f"the {rw}x{rh} px region to copy from the {width}x{height} image holds {rh * rw:.3g} "
                         f"pixels, over the limit of {limit:.3g} (${IMAGE_PIXELS_VARIABLE})")


def resize(patch: np.ndarray, out) -> np.ndarray:
    """Resize to ``out`` (h, w): area averaging when shrinking, bilinear when enlarging."""
    oh, ow = int(out[0]), int(out[1])
    if patch.shape[:2] == (oh, ow):
        return np.ascontiguousarray(patch)
    shrink = patch.shape[0] * patch.shape[1] > oh * ow
    return cv2.resize(patch, (ow, oh), interpolation=cv2.INTER_AREA if shrink else cv2.INTER_LINEAR)


def sample(image: np.ndarray, centre, region, out) -> np.ndarray:
    """Crop ``region`` (h, w) around ``centre`` and resample it to ``out`` (h, w).

    A shrink by k >= 2 first averages k x k blocks (OpenCV's fast integer path; a non-integer
    area resize of a ~1000 px region costs 2-3x more), then maps the exact region onto the
    output grid bilinearly (the remaining factor is below 2). Blocks wholly outside the image
    are replicated, not averaged: for uint8 images (the trackers' input) the result is
    identical to averaging the whole edge-replicated region; float images may differ in the
    last bit."""
    return sampler(image.shape, centre, region, out)(image)


def sampler(shape, centre, region, out) -> Callable[[np.ndarray], np.ndarray]:
    """:func:`sample` with its geometry worked out once, for images of ``shape`` (H, W[, C]):
    the DSST resamples the same working patch to the same 33 scales every frame."""
    oh, ow = int(out[0]), int(out[1])
    k = int(min(region[0] / oh, region[1] / ow))
    if k < 2:
        cut = cropper(shape, centre, region)
        return lambda image: resize(cut(image), (oh, ow))
    ch, cw = (int(np.ceil(region[0] / k)) + 2) * k, (int(np.ceil(region[1] / k)) + 2) * k
    y0, x0 = _origin(centre[0], ch), _origin(centre[1], cw)
    # k x k blocks wholly outside the image average replicated edge pixels, so all of them on
    # one side of a block row (column) are equal: average only the first, replicate the rest
    top, bottom = _blocks_outside(y0, ch // k, k, shape[0])
    left, right = _blocks_outside(x0, cw // k, k, shape[1])
    cut = _cropper_at(shape, y0 + top * k, x0 + left * k, ch - (top + bottom) * k, cw - (left + right) * k)
    # output pixel u samples image row cy + (u - (oh - 1) / 2) * region_h / oh; small row i
    # averages image rows y0 + k i .. y0 + k i + k - 1, centred at y0 + k i + (k - 1) / 2
    sy, sx = region[0] / oh, region[1] / ow
    ty = (centre[0] - (oh - 1) / 2 * sy - y0 - (k - 1) / 2) / k
    tx = (centre[1] - (ow - 1) / 2 * sx - x0 - (k - 1) / 2) / k
    warp = np.array([[sx / k, 0.0, tx], [0.0, sy / k, ty]])

    def run(image: np.ndarray) -> np.ndarray:
        part = cut(image)
        small = cv2.resize(part, (part.shape[1] // k, part.shape[0] // k), interpolation=cv2.INTER_AREA)
        if top or bottom or left or right:
            small = cv2.copyMakeBorder(small, top, bottom, left, right, cv2.BORDER_REPLICATE)
        return cv2.warpAffine(small, warp, (ow, oh), flags=cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP,
                              borderMode=cv2.BORDER_REPLICATE)

    return run


def round_half_away(x):
    """MATLAB's ``round``: halves away from zero (numpy rounds them to even)."""
    x = np.asarray(x, dtype=float)
    return np.sign(x) * np.floor(np.abs(x) + 0.5)


def whole_pixel_crop(image: np.ndarray, centre, size) -> np.ndarray:
    """The authors' crop (``get_pixels``, DSST's ``get_scale_sample``): ``size`` (h, w) whole pixels,
    1-based ``floor(pos) + (1:h) - floor(h/2)``, edges replicated. The pixel ``floor(centre)``
    sits at index h // 2 - 1: half a pixel above and left of the middle when h, w are even."""
    return whole_pixel_cropper(image.shape, centre, size)(image)


def whole_pixel_cropper(shape, centre, size) -> Callable[[np.ndarray], np.ndarray]:
    """:func:`whole_pixel_crop` with its geometry worked out once, for images of ``shape``."""
    h, w = int(size[0]), int(size[1])
    y0 = int(np.floor(centre[0])) + 1 - h // 2
    x0 = int(np.floor(centre[1])) + 1 - w // 2
    return _cropper_at(shape, y0, x0, h, w)


def resize_auto(patch: np.ndarray, out) -> np.ndarray:
    """The authors' compiled ``mexResize(patch, out, 'auto')``: OpenCV bilinear when the new
    width exceeds the old *height*, area averaging otherwise. Their mexResize.cpp means "when
    the width grows", but compares with ``oldSize.height`` of a Mat that mexopencv hands over
    untransposed, i.e. the number of rows; on the square search patches the two agree, on the
    DSST's non-square scale samples they do not (tests/numerics/test_patches.py)."""
    oh, ow = int(out[0]), int(out[1])
    grows = ow > patch.shape[0]
    return cv2.resize(patch, (ow, oh), interpolation=cv2.INTER_LINEAR if grows else cv2.INTER_AREA)


def whole_pixel_sample(image: np.ndarray, centre, region, out) -> np.ndarray:
    """The search patch as the authors' code samples it (STRCF's and DR²Track's ``get_pixels``):
    :func:`whole_pixel_crop` of ``round(region)`` pixels (a side below 1 becomes 2), then
    :func:`resize_auto` to ``out``."""
    return whole_pixel_sampler(image.shape, centre, region, out)(image)


def whole_pixel_sampler(shape, centre, region, out, resize: str = "auto",
                        resized=None) -> Callable[[np.ndarray], np.ndarray]:
    """:func:`whole_pixel_sample` with its geometry worked out once, for images of ``shape``.
    ``resize`` 'matlab_bicubic': MATLAB's ``imresize`` instead of :func:`resize_auto`; with
    ``resized`` (h, w), ``region`` is floored and the crop resized to ``resized`` instead of
    ``out`` (CSR-DCF's template, which may exceed ``out``'s whole cells by less than a cell: the
    features take the whole cells, fhog with the remainder's gradients, as theirs)."""
    if resized is None:
        size = [int(v) if v >= 1 else 2 for v in round_half_away(region)]
    else:
        size = [int(v) if v >= 1 else 2 for v in np.floor(region)]
    cut = whole_pixel_cropper(shape, centre, size)
    if resize == "auto" and resized is None:
        return lambda image: resize_auto(cut(image), out)
    to = out if resized is None else resized
    scale = imresize if resize == "matlab_bicubic" else resize_auto
    return lambda image: scale(cut(image), (int(to[0]), int(to[1])))


def _blocks_outside(start: int, n: int, k: int, size: int) -> tuple[int, int]:
    """Of ``n`` blocks of ``k`` pixels from ``start``, how many beyond the first one wholly
    before pixel 0, and beyond the first one wholly after pixel size - 1, can be replicated."""
    before = min(max(-start // k, 0), n)
    after = min(max(n - ((size - 1 - start) // k + 1), 0), n)
    return max(before - 1, 0), max(after - 1, 0)  # a region wholly off one side keeps one block
