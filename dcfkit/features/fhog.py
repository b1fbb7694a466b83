"""Felzenszwalb HOG ("fhog") as computed by Piotr Dollar's toolbox.

STRCF, BACF and DR2Track extract hand-crafted features through ``get_fhog``,
which calls Piotr's ``fhog(single(im), cell_size, 9, 0.2)`` and keeps the first
31 of its 32 channels.  This module reimplements that descriptor with numpy and
cv2 (Felzenszwalb et al., "Object Detection with Discriminatively Trained
Part-Based Models", PAMI 2010, Sec. 6.2-6.3):

1. gradients by centred differences ``(I[x+1] - I[x-1]) / 2`` (one-sided and
   not halved on the image border); in colour images every pixel takes the
   gradient of the channel with the largest magnitude;
2. each pixel's magnitude is split linearly between the two orientation bins
   nearest to its direction (``2 * n_orients`` bins over ``[0, 2pi)``, bin
   ``k`` centred at ``pi k / n_orients``) and bilinearly between the 4 nearest
   cells; histograms are divided by ``cell_size**2`` and border cells
   multiplied by ``8/7``, as in Piotr's ``gradHist``;
3. each cell is divided by the gradient energy (contrast-insensitive histogram)
   of each of the 4 2x2-cell blocks containing it, and clipped at ``clip``.  The
   27 orientation channels sum the 4 normalisations times 0.5; the 4 texture
   channels sum the 18 contrast-sensitive orientations of one normalisation
   times 0.2357.

Deviation from Piotr's ``fhog``: it bins orientations *hard* (``softBin=-1``:
nearest bin only); here soft binning is the default and
``soft_orientation=False`` gives the toolbox's binning.  The all-zero 32nd
"truncation" channel is not produced.

Speed: about 1 ms for a 200x200x3 patch.  In this workload page faults on
freshly allocated memory cost as much as the arithmetic, so the large
intermediates live in per-thread buffers that are reused between calls with the
same geometry.
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from functools import lru_cache

import cv2
import numpy as np

__all__ = ["fhog", "fhog_channels"]

_TEXTURE_SCALE = 0.2357  # Piotr's constant for the 4 texture channels
# (row, col) offsets into the edge-padded grid of block normalisers, in the order
# of Piotr's texture channels: the 2x2 block below-right of a cell, above-right,
# below-left, above-left.
_BLOCK_OFFSETS = ((1, 1), (0, 1), (1, 0), (0, 0))


def fhog_channels(n_orients: int = 9) -> int:
    """Number of fhog channels: ``3 * n_orients + 4`` (31 for 9 orientations)."""
    return 3 * n_orients + 4


def fhog(
    image: np.ndarray,
    cell_size: int = 4,
    n_orients: int = 9,
    clip: float = 0.2,
    *,
    batch: bool = False,
    soft_orientation: bool = True,
) -> np.ndarray:
    """Felzenszwalb HOG of one image, or of a batch of equally sized images.

    Args:
        image: ``(H, W)`` or ``(H, W, 3)``; with ``batch=True`` ``(N, H, W)`` or
            ``(N, H, W, 3)``.  ``uint8`` (0..255) or ``float32`` on the same
            scale (equal values give identical features).  The order of the
            colour channels does not matter.
        cell_size: cell side in pixels; ``H, W >= 2 * cell_size``.  Rows and
            columns beyond the last whole cell only serve as gradient neighbours.
        n_orients: contrast-insensitive orientation bins (``2 * n_orients``
            contrast-sensitive ones).
        clip: truncation of each normalised histogram value.
        batch: the first axis indexes images; they are computed together in one
            vectorised pass.
        soft_orientation: split each magnitude between the two nearest
            orientation bins (default); ``False`` puts it in the nearest bin, as
            Piotr's toolbox does.

    Returns:
        ``(3 * n_orients + 4, H // cell_size, W // cell_size)`` float32,
        C-contiguous (with ``batch=True``: ``(N, ...)``).  Channels
        ``[0, 2n)``: contrast-sensitive orientations; ``[2n, 3n)``:
        contrast-insensitive; ``[3n, 3n + 4)``: texture (gradient energy).

    Raises:
        ValueError: wrong shape or dtype, image smaller than 2x2 cells, or a
            bad parameter.
    """
    _check_params(cell_size, n_orients, clip)
    imgs = _as_stack(image, batch, cell_size)
    hist = _cell_histograms(imgs, cell_size, 2 * n_orients, soft_orientation)
    out = _normalise(hist, n_orients, clip, cell_size)
    return out if batch else out[0]


# ---------------------------------------------------------------------------- input


def _check_params(cell_size, n_orients, clip) -> None:
    if isinstance(cell_size, bool) or not isinstance(cell_size, (int, np.integer)) or cell_size < 1:
        raise ValueError(f"fhog: cell_size must be a positive int, got {cell_size!r}")
    if isinstance(n_orients, bool) or not isinstance(n_orients, (int, np.integer)) or n_orients < 1:
        raise ValueError(f"fhog: n_orients must be a positive int, got {n_orients!r}")
    if not clip > 0:
        raise ValueError(f"fhog: clip must be > 0, got {clip!r}")


def _as_stack(image, batch: bool, cell_size: int) -> np.ndarray:
    """Validate ``image``; return it as ``(N, H, W)`` or ``(N, H, W, 3)`` (a view)."""
    if not isinstance(image, np.ndarray):
        raise ValueError(f"fhog: image must be a numpy array, got {type(image).__name__}")
    if batch:
        accepted = "(N, H, W) or (N, H, W, 3) with batch=True"
    else:
        accepted = "(H, W) or (H, W, 3); pass batch=True for a stack of images"
    gray_ndim = 3 if batch else 2
    shape = image.shape
    if not (image.ndim == gray_ndim or (image.ndim == gray_ndim + 1 and shape[-1] == 3)):
        raise ValueError(f"fhog: image of shape {shape} not accepted; expected {accepted}")
    if image.dtype != np.uint8 and image.dtype != np.float32:
        raise ValueError(
            f"fhog: image dtype {image.dtype} not accepted; expected uint8 (0..255) "
            "or float32 on the same scale, e.g. image.astype(np.float32)"
        )
    stack = image if batch else image[None]
    h, w = stack.shape[1:3]
    if h < 2 * cell_size or w < 2 * cell_size:
        raise ValueError(
            f"fhog: image of shape {shape} is too small: height and width must be at "
            f"least 2 cells = {2 * cell_size} pixels for cell_size={cell_size}"
        )
    return stack


# ------------------------------------------------------------------ reused buffers

_local = threading.local()


def _workspace(key) -> dict:
    """Per-thread dict of scratch arrays for one input geometry (4 kept, LRU)."""
    cache = getattr(_local, "cache", None)
    if cache is None:
        cache = _local.cache = OrderedDict()
    ws = cache.get(key)
    if ws is None:
        ws = cache[key] = {}
        if len(cache) > 4:
            cache.popitem(last=False)
    else:
        cache.move_to_end(key)
    return ws


def _buf(ws: dict, name: str, shape, dtype=np.float32) -> np.ndarray:
    a = ws.get(name)
    if a is None:
        a = ws[name] = np.empty(shape, dtype)
    return a


# ------------------------------------------------------------------------ gradients


def _gradients(imgs: np.ndarray, rows: int, cols: int, ws: dict) -> tuple[np.ndarray, np.ndarray]:
    """Gradient magnitude and direction over the top-left ``rows x cols`` pixels.

    Args:
        imgs: ``(N, H, W)`` or ``(N, H, W, 3)`` uint8/float32, ``H >= rows``,
            ``W >= cols``.
        ws: scratch buffers (the results live there).

    Returns:
        ``mag, theta``: ``(N * rows, cols)`` float32; ``theta`` in ``[0, 2pi]``
        is the angle of ``(gx, gy)``, x to the right and y downwards.  Colour
        images use, per pixel, the channel of largest magnitude (the first on
        ties).
    """
    n = imgs.shape[0]
    # One row/column beyond the cells keeps centred differences at their edge.
    imgs = imgs[:, : rows + 1, : cols + 1]
    h, w = imgs.shape[1:3]
    if n == 1 and imgs[0, 0].flags.c_contiguous:
        tall = imgs[0]  # cv2 takes row-strided views
    else:
        tall = np.ascontiguousarray(imgs).reshape((n * h, w) + imgs.shape[3:])
    if tall.ndim == 3:
        planes = cv2.split(tall, [_buf(ws, f"plane{c}", (n * h, w), tall.dtype) for c in range(3)])
    else:
        planes = [tall]

    mags, gxs, gys = [], [], []
    for c, plane in enumerate(planes):
        gx = _buf(ws, f"gx{c}", (n * h, w))
        gy = _buf(ws, f"gy{c}", (n * h, w))
        _central_differences(plane, gx, gy, n)
        mags.append(cv2.magnitude(gx, gy, magnitude=_buf(ws, f"mag{c}", (n * h, w))))
        gxs.append(gx)
        gys.append(gy)
    mag, gx, gy = mags[0], gxs[0], gys[0]
    if len(planes) > 1:
        better = _buf(ws, "better", (n * h, w), np.uint8)
        for c in (1, 2):
            cv2.compare(mags[c], mag, cv2.CMP_GT, dst=better)
            cv2.copyTo(gxs[c], better, gx)
            cv2.copyTo(gys[c], better, gy)
            cv2.max(mag, mags[c], dst=mag)
    theta = cv2.phase(gx, gy, angle=_buf(ws, "theta", (n * h, w)))
    if h != rows or w != cols:
        mag = np.ascontiguousarray(mag.reshape(n, h, w)[:, :rows, :cols]).reshape(n * rows, cols)
        theta = np.ascontiguousarray(theta.reshape(n, h, w)[:, :rows, :cols]).reshape(n * rows, cols)
    return mag, theta


def _central_differences(plane: np.ndarray, gx: np.ndarray, gy: np.ndarray, n: int) -> None:
    """``[-1, 0, 1] / 2`` derivatives of ``n`` images stacked as ``(n * h, w)``.

    Interior pixels get ``(I[p+1] - I[p-1]) / 2``, border pixels ``I[1] - I[0]``
    and ``I[-1] - I[-2]`` (Piotr's ``grad1``); results go to ``gx``, ``gy``.
    """
    kw = dict(ksize=1, scale=0.5, borderType=cv2.BORDER_REPLICATE)
    cv2.Sobel(plane, cv2.CV_32F, 1, 0, dst=gx, **kw)
    cv2.Sobel(plane, cv2.CV_32F, 0, 1, dst=gy, **kw)
    # Replicated borders give half the one-sided difference.
    gx[:, 0] *= 2
    gx[:, -1] *= 2
    # In a stack the rows next to each seam saw the neighbouring image.
    p = plane.reshape(n, -1, plane.shape[1])
    g = gy.reshape(n, -1, gy.shape[1])
    np.subtract(p[:, 1], p[:, 0], out=g[:, 0], dtype=np.float32)
    np.subtract(p[:, -1], p[:, -2], out=g[:, -1], dtype=np.float32)


# ----------------------------------------------------------------------- histograms


@lru_cache(maxsize=32)
def _cell_axis(length: int, cell_size: int) -> tuple[np.ndarray, np.ndarray]:
    """Bilinear cell assignment of ``length`` pixels along one axis.

    Pixel ``p`` sits at cell coordinate ``t = (p + 0.5) / cell_size - 0.5`` and
    gives ``1 - d`` to cell ``floor(t)`` and ``d = t - floor(t)`` to the next.

    Returns:
        ``lower``: ``(length,)`` intp, ``floor(t) + 1`` (cells padded by one on
        each side); ``d``: ``(length,)`` float64.
    """
    t = (np.arange(length) + 0.5) / cell_size - 0.5
    lower = np.floor(t)
    return (lower + 1).astype(np.intp), t - lower


@lru_cache(maxsize=8)
def _scatter_plan(n: int, rows: int, cols: int, cell_size: int, slots: int):
    """Tables for scattering pixels into ``(n * rows, cols // cell_size + 2, slots)``.

    Pixel rows stay separate in the scatter (they are pooled densely after it);
    columns go bilinearly to padded cells; ``slots`` orientation slots.

    Returns:
        ``base``: ``(4, n * rows * cols)`` intp, flat target of each pixel for
        (lower cell, bin o0), (lower, o0 + 1), (upper, o0), (upper, o0 + 1),
        less ``o0``.  ``wx``: ``(2, 1, n * rows * cols)`` float64, weights of the
        lower and upper cell.  ``wy``: ``(3, cell_size)`` float64, weight of a
        pixel at row ``r`` of a cell to the cell above (0), its own (1) and the
        one below (2).
    """
    lower, d = _cell_axis(cols, cell_size)
    wbp = cols // cell_size + 2
    row_start = np.arange(n * rows, dtype=np.intp)[:, None] * wbp
    base = ((row_start + lower[None, :]) * slots).ravel()
    offsets = np.array([0, 1, slots, slots + 1], dtype=np.intp)
    base4 = base[None, :] + offsets[:, None]
    wx = np.empty((2, 1, n * rows * cols))
    wx[0, 0] = np.tile(1.0 - d, n * rows)
    wx[1, 0] = np.tile(d, n * rows)

    lower_r, d_r = _cell_axis(cell_size, cell_size)  # rows of one cell
    wy = np.zeros((3, cell_size))
    for r in range(cell_size):
        k = int(lower_r[r])  # 0: shares with the cell above, 1: with the one below
        wy[k, r] += 1.0 - d_r[r]
        wy[k + 1, r] += d_r[r]
    for a in (base4, wx, wy):
        a.setflags(write=False)
    return base4, wx, wy


def _cell_histograms(
    imgs: np.ndarray, cell_size: int, n_bins: int, soft_orientation: bool = True
) -> np.ndarray:
    """Un-normalised orientation histograms of all cells (Piotr's ``gradHist``).

    Each pixel's gradient magnitude goes to the two orientation bins nearest to
    its direction with linear weights (bin ``k`` centred at
    ``2pi k / n_bins``; only the nearest if not ``soft_orientation``) and to the
    4 nearest cell centres with bilinear weights.  Sums are divided by
    ``cell_size**2``; cells on the border are multiplied by ``8/7`` (corners
    twice), which Piotr's code does to make up for their missing outer half.

    Args:
        imgs: ``(N, H, W)`` or ``(N, H, W, 3)`` uint8/float32.
        cell_size: cell side in pixels.
        n_bins: orientation bins over ``[0, 2pi)``.
        soft_orientation: linear (True) or nearest-bin (False) orientation
            binning.

    Returns:
        ``(N, n_bins, H // cell_size, W // cell_size)`` float32.
    """
    n = imgs.shape[0]
    hb, wb = imgs.shape[1] // cell_size, imgs.shape[2] // cell_size
    rows, cols = hb * cell_size, wb * cell_size
    ws = _workspace((imgs.shape, imgs.dtype.char, cell_size, n_bins, soft_orientation))
    mag, theta = _gradients(imgs, rows, cols, ws)

    # Orientation: bins o0 and o0 + 1; slot n_bins is bin 0 again.
    slots, npix = n_bins + 1, n * rows * cols
    o = theta.reshape(npix)
    o *= np.float32(n_bins / (2 * np.pi))
    mag = mag.reshape(npix)
    o0 = _buf(ws, "o0", npix, np.intp)
    base4, wx, wy = _scatter_plan(n, rows, cols, cell_size, slots)
    if soft_orientation:
        np.copyto(o0, o, casting="unsafe")  # floor, as o >= 0
        np.minimum(o0, n_bins - 1, out=o0)  # theta rounded up to 2pi
        frac = _buf(ws, "frac", npix)
        np.copyto(frac, o0, casting="unsafe")
        np.subtract(o, frac, out=frac)
        mo = _buf(ws, "mo", (1, 2, npix), np.float64)  # weights of o0, o0 + 1
        np.multiply(mag, frac, out=frac)
        np.copyto(mo[0, 1], frac)
        np.subtract(mag, frac, out=mag)
        np.copyto(mo[0, 0], mag)
        idx = np.add(base4, o0, out=_buf(ws, "idx", base4.shape, np.intp))
        weights = np.multiply(wx, mo, out=_buf(ws, "weights", (2, 2, npix), np.float64))
    else:
        o += np.float32(0.5)
        np.copyto(o0, o, casting="unsafe")  # round; bin n_bins lands in slot n_bins
        idx = np.add(base4[::2], o0, out=_buf(ws, "idx", (2, npix), np.intp))
        weights = np.multiply(wx[:, 0], mag, out=_buf(ws, "weights", (2, npix), np.float64))
    wbp = wb + 2
    t = np.bincount(idx.reshape(-1), weights.reshape(-1), minlength=n * rows * wbp * slots)

    # Rows: a pixel at row r of cell c feeds cells c-1, c and c+1 with wy[:, r].
    t = t.reshape(n, hb, cell_size, wbp * slots)
    y = np.matmul(wy, t, out=_buf(ws, "y", (n, hb, 3, wbp * slots), np.float64))
    h = _buf(ws, "h", (n, hb, wbp * slots), np.float64)
    np.copyto(h, y[:, :, 1])
    h[:, 1:] += y[:, :-1, 2]
    h[:, :-1] += y[:, 1:, 0]

    h = h.reshape(n, hb, wbp, slots)[:, :, 1 : wb + 1]
    h[..., 0] += h[..., n_bins]
    hist = np.empty((n, n_bins, hb, wb), np.float32)
    np.copyto(hist, h[..., :n_bins].transpose(0, 3, 1, 2), casting="same_kind")
    hist *= np.float32(1.0 / cell_size**2)
    edge = np.float32(8.0 / 7.0)
    hist[:, :, 0] *= edge
    hist[:, :, -1] *= edge
    hist[:, :, :, 0] *= edge
    hist[:, :, :, -1] *= edge
    return hist


# -------------------------------------------------------------------- normalisation


def _normalise(hist: np.ndarray, n_orients: int, clip: float, cell_size: int) -> np.ndarray:
    """Block-normalise, clip and project cell histograms into fhog channels.

    Args:
        hist: ``(N, 2 * n_orients, hb, wb)`` float32 (``_cell_histograms``),
            ``hb, wb >= 2``.

    Returns:
        ``(N, 3 * n_orients + 4, hb, wb)`` float32, C-contiguous.
    """
    n, _, hb, wb = hist.shape
    no = 3 * n_orients  # orientation channels
    # Orientation features: contrast-sensitive then -insensitive histograms.
    feats = np.empty((n, no, hb * wb), np.float32)
    flat = hist.reshape(n, 2 * n_orients, hb * wb)
    feats[:, : 2 * n_orients] = flat
    insens = feats[:, 2 * n_orients :]
    np.add(flat[:, :n_orients], flat[:, n_orients:], out=insens)

    # 1 / sqrt(energy of each 2x2 block + eps), edge-padded to (hb + 1, wb + 1)
    # so that every cell has 4 blocks.
    energy = np.einsum("nok,nok->nk", insens, insens).reshape(n, hb, wb)
    blocks = energy[:, :-1, :-1] + energy[:, 1:, :-1]
    blocks += energy[:, :-1, 1:]
    blocks += energy[:, 1:, 1:]
    blocks += np.float32(1e-4 / 4 / cell_size**4)  # Piotr's eps on this scale
    inv = np.empty((n, hb + 1, wb + 1), np.float32)
    core = inv[:, 1:hb, 1:wb]
    np.sqrt(blocks, out=core)
    np.divide(np.float32(1.0), core, out=core)
    inv[:, 0, 1:wb] = core[:, 0]
    inv[:, hb, 1:wb] = core[:, -1]
    inv[:, :, 0] = inv[:, :, 1]
    inv[:, :, wb] = inv[:, :, wb - 1]

    out = np.zeros((n, no + 4, hb * wb), np.float32)
    orient = out[:, :no]
    tmp = np.empty_like(feats)
    norm = np.empty((n, 1, hb, wb), np.float32)
    clip = np.float32(clip)
    for k, (dr, dc) in enumerate(_BLOCK_OFFSETS):
        np.copyto(norm[:, 0], inv[:, dr : dr + hb, dc : dc + wb])
        np.multiply(feats, norm.reshape(n, 1, hb * wb), out=tmp)
        np.minimum(tmp, clip, out=tmp)
        orient += tmp
        np.sum(tmp[:, : 2 * n_orients], axis=1, out=out[:, no + k])
    orient *= np.float32(0.5)
    out[:, no:] *= np.float32(_TEXTURE_SCALE)
    return out.reshape(n, no + 4, hb, wb)
