"""Felzenszwalb HOG ("fhog") as computed by Piotr Dollar's toolbox.

STRCF, BACF and DR2Track extract hand-crafted features through ``get_fhog``,
which calls Piotr's ``fhog(single(im), cell_size, 9, 0.2)`` and keeps the first
31 of its 32 channels.  This module reimplements that descriptor with numpy and
cv2 (Felzenszwalb et al., "Object Detection with Discriminatively Trained
Part-Based Models", PAMI 2010, Sec. 6):

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

Like Piotr's ``fhog`` (``softBin=-1``) orientations are binned *hard* (nearest
bin only) by default; ``soft_orientation=True`` splits each magnitude between
the two nearest bins instead.  The all-zero 32nd "truncation" channel is not
produced.

Speed (2-core VM, one thread): about 1.6 ms for a 200x200x3 patch, 1 ms for a
batch of 33 32x16x3 patches.  The scatter of pixels into cells (``np.add.at``)
runs on chunks of cell rows so that its target stays in cache.  Intermediates
live in per-thread scratch buffers reused by calls of the same geometry (the
last 4 geometries, a few MB each): on this machine a page fault costs about
2 us and glibc hands freed large blocks back to the kernel, so fresh large
arrays (``np.bincount``'s output, say) cost more than the arithmetic on them.
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from functools import lru_cache
from typing import NamedTuple

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
    soft_orientation: bool = False,
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
            orientation bins; ``False`` (default) puts it in the nearest bin, as
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
    if imgs.shape[0] == 0:
        hb, wb = imgs.shape[1] // cell_size, imgs.shape[2] // cell_size
        return np.zeros((0, fhog_channels(n_orients), hb, wb), np.float32)
    ws = _workspace((imgs.shape, imgs.dtype.char, cell_size, n_orients))
    hist = _histograms(imgs, cell_size, 2 * n_orients, soft_orientation, ws)
    out = _normalise(hist, n_orients, clip, cell_size, ws)
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
    """The scratch array ``name`` of ``ws``, (re)allocated to ``shape``/``dtype``."""
    a = ws.get(name)
    if a is None or a.shape != (shape if isinstance(shape, tuple) else (shape,)) or a.dtype != dtype:
        a = ws[name] = np.empty(shape, dtype)
    return a


# ------------------------------------------------------------------------ gradients


def _gradients(imgs: np.ndarray, rows: int, cols: int, ws: dict) -> tuple[np.ndarray, np.ndarray]:
    """Gradient magnitude and direction over the top-left ``rows x cols`` pixels.

    The images are placed side by side (cv2 filters pay per image row, and batch
    images are narrow), so results are laid out ``(row, image, column)``.

    Args:
        imgs: ``(N, H, W)`` or ``(N, H, W, 3)`` uint8/float32, ``H >= rows``,
            ``W >= cols``.
        ws: scratch buffers (the results live there).

    Returns:
        ``mag, theta``: ``(rows, N, cols)`` float32, C-contiguous; ``theta`` in
        ``[0, 2pi]`` is the angle of ``(gx, gy)``, x to the right and y
        downwards.  Colour images use, per pixel, the channel of largest
        magnitude (the first one on ties).
    """
    n = imgs.shape[0]
    # One row/column beyond the cells keeps centred differences at their edge.
    imgs = imgs[:, : rows + 1, : cols + 1]
    h, w = imgs.shape[1:3]
    if n == 1 and imgs[0, 0].flags.c_contiguous:
        wide = imgs[0]  # cv2 takes row-strided views
    else:
        wide = np.ascontiguousarray(imgs.swapaxes(0, 1)).reshape((h, n * w) + imgs.shape[3:])
    if wide.ndim == 3:
        planes = cv2.split(wide, [_buf(ws, f"plane{c}", (h, n * w), wide.dtype) for c in range(3)])
    else:
        planes = [wide]

    # The differences are taken with the opposite sign, so that arctan2 of them
    # plus pi is the gradient direction in [0, 2pi].
    mags, gxs, gys = [], [], []
    for c, plane in enumerate(planes):
        gx = _buf(ws, f"gx{c}", (h, n * w))
        gy = _buf(ws, f"gy{c}", (h, n * w))
        _negated_differences(plane, gx, gy, n)
        # numpy, not cv2.magnitude: OpenCV's SIMD path rounds the last bit differently
        # depending on buffer alignment, which made tracking non-deterministic
        mag = np.multiply(gx, gx, out=_buf(ws, f"mag{c}", (h, n * w)))
        mag += np.multiply(gy, gy, out=_buf(ws, "gy_squared", (h, n * w)))
        mags.append(np.sqrt(mag, out=mag))
        gxs.append(gx)
        gys.append(gy)
    mag, gx, gy = mags[0], gxs[0], gys[0]
    if len(planes) > 1:
        better = _buf(ws, "better", (h, n * w), np.uint8)
        for c in (1, 2):
            cv2.compare(mags[c], mag, cv2.CMP_GT, dst=better)
            cv2.copyTo(gxs[c], better, gx)
            cv2.copyTo(gys[c], better, gy)
            cv2.max(mag, mags[c], dst=mag)
    theta = np.arctan2(gy, gx, out=_buf(ws, "theta", (h, n * w)))  # cv2.phase is 1e-4 rad off
    theta += np.float32(np.pi)
    mag, theta = mag.reshape(h, n, w), theta.reshape(h, n, w)
    if h != rows or w != cols:
        mag = _copy(mag[:rows, :, :cols], _buf(ws, "mag_crop", (rows, n, cols)))
        theta = _copy(theta[:rows, :, :cols], _buf(ws, "theta_crop", (rows, n, cols)))
    return mag, theta


def _copy(src: np.ndarray, dst: np.ndarray) -> np.ndarray:
    np.copyto(dst, src)
    return dst


def _negated_differences(plane: np.ndarray, gx: np.ndarray, gy: np.ndarray, n: int) -> None:
    """Minus the ``[-1, 0, 1] / 2`` derivatives of ``n`` images side by side.

    ``plane`` is ``(h, n * w)``.  Interior pixels get ``-(I[p+1] - I[p-1]) / 2``,
    border pixels ``-(I[1] - I[0])`` and ``-(I[-1] - I[-2])`` (Piotr's ``grad1``,
    negated); results go to ``gx``, ``gy`` (float32, same shape).
    """
    kw = dict(ksize=1, scale=-0.5, borderType=cv2.BORDER_REPLICATE)
    cv2.Sobel(plane, cv2.CV_32F, 1, 0, dst=gx, **kw)
    cv2.Sobel(plane, cv2.CV_32F, 0, 1, dst=gy, **kw)
    # Replicated borders give half the one-sided difference.
    gy[0] *= 2
    gy[-1] *= 2
    if n == 1:
        gx[:, 0] *= 2
        gx[:, -1] *= 2
    else:  # the columns at each seam saw the neighbouring image
        p = plane.reshape(plane.shape[0], n, -1)
        g = gx.reshape(gx.shape[0], n, -1)
        np.subtract(p[:, :, 0], p[:, :, 1], out=g[:, :, 0], dtype=np.float32)
        np.subtract(p[:, :, -2], p[:, :, -1], out=g[:, :, -1], dtype=np.float32)


# ----------------------------------------------------------------------- histograms


def _cell_axis(length: int, cell_size: int) -> tuple[np.ndarray, np.ndarray]:
    """Bilinear cell assignment of ``length`` pixels along one axis.

    Pixel ``p`` sits at cell coordinate ``t = (p + 0.5) / cell_size - 0.5`` and
    gives ``1 - d`` to cell ``floor(t)`` and ``d = t - floor(t)`` to the next.

    Returns:
        ``left``: ``(length,)`` intp, ``floor(t)`` (-1 left of the first cell
        centre); ``d``: ``(length,)`` float64.
    """
    t = (np.arange(length) + 0.5) / cell_size - 0.5
    left = np.floor(t)
    return left.astype(np.intp), t - left


_FAST_UFUNC_AT = np.lib.NumpyVersion(np.__version__) >= "1.25.0"  # ufunc.at got a fast path
_SCATTER_BYTES = 1 << 19  # target size of one chunk's float64 scatter output (L2)


class _Plan(NamedTuple):
    """Geometry of the chunked scatter (see ``_scatter_plan``)."""

    cells: int  # cell rows per chunk
    prows: int  # rows of a full chunk's scatter output
    base: np.ndarray  # (4, chunk pixels) intp
    wx: np.ndarray  # (2, 1, chunk pixels) float64
    wy: np.ndarray  # (1, L) float64
    scale: np.ndarray  # (hb, wb) float32


@lru_cache(maxsize=8)
def _scatter_plan(n: int, rows: int, cols: int, cell_size: int, slots: int) -> _Plan:
    """Tables for scattering pixels into per-row cell histograms (cached).

    The pixels ``(rows, n, cols)`` of ``_gradients`` are scattered one chunk of
    ``cells`` cell rows at a time into ``(prows, n, cols // cell_size, slots)``
    float64: pixel rows stay separate (they are pooled densely afterwards),
    columns go bilinearly to cells.  Zero rows above and below the chunk's
    pixels make the row window of local cell ``j`` (``-1 .. cells``) start at
    row ``(j + 1) * cell_size``.

    Returns:
        ``_Plan`` with ``base``: flat target of each pixel of a chunk for
        (left cell, orientation slot 0), (left, 1), (right, 0), (right, 1);
        ``wx``: weights of the left and right cell; ``wy``: row weights of a
        cell over its ``L`` (about ``2 * cell_size``) window rows; ``scale``:
        ``1 / cell_size**2`` times ``8/7`` per image border the cell touches.
    """
    hb, wb = rows // cell_size, cols // cell_size
    # Row r of a cell sits at cell coordinate t = (r + 0.5) / cell_size - 0.5
    # relative to it and feeds the cell floor(t) with 1 - frac(t) and the next
    # one with frac(t): over the rows of the cells above, at and below, a
    # cell's weights are the ramp 1 - |t|; keep its non-zero part.
    t = (np.arange(3 * cell_size) + 0.5) / cell_size - 1.5
    wy = np.maximum(0.0, 1.0 - np.abs(t))
    first, last = (int(i) for i in np.flatnonzero(wy)[[0, -1]])
    wy = wy[first : last + 1][None]
    pad = 2 * cell_size - first  # zero rows above a chunk's pixels
    pad_below = first + wy.shape[1] - cell_size
    row_len = n * wb * slots
    cells = (_SCATTER_BYTES // (8 * row_len) - pad - pad_below) // cell_size
    cells = min(hb, max(cells, 8))  # chunks of fewer cell rows pay more than they save
    cells = -(-hb // -(-hb // cells))  # same number of chunks, equal sizes

    # Columns: cells left and right of each pixel; a cell outside the image
    # gets weight 0 (and any valid index).
    left, d = _cell_axis(cols, cell_size)
    right = left + 1
    wx_row = np.stack([np.where(left >= 0, 1.0 - d, 0.0), np.where(right < wb, d, 0.0)])
    cell_row = np.stack([np.maximum(left, 0), np.minimum(right, wb - 1)])  # (2, cols)
    row = np.arange(cells * cell_size)[:, None] + pad
    row_start = (row * n + np.arange(n)[None, :]) * wb  # (rows, n)
    base = (row_start[None, :, :, None] + cell_row[:, None, None, :]) * slots  # (2, rows, n, cols)
    base = (base.reshape(2, 1, -1) + np.array([[0], [1]])).reshape(4, -1)
    wx = np.tile(wx_row, n * cells * cell_size)[:, None]  # (2, 1, chunk pixels)

    edge_r = np.ones(hb)
    edge_r[[0, -1]] = 8.0 / 7.0
    edge_c = np.ones(wb)
    edge_c[[0, -1]] = 8.0 / 7.0
    scale = (np.outer(edge_r, edge_c) / cell_size**2).astype(np.float32)
    for a in (base, wx, wy, scale):
        a.setflags(write=False)
    return _Plan(cells, pad + cells * cell_size + pad_below, base, wx, wy, scale)


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
    hist = _histograms(imgs, cell_size, n_bins, soft_orientation, {})
    return hist.transpose(1, 0, 2, 3).copy()


def _histograms(
    imgs: np.ndarray, cell_size: int, n_bins: int, soft_orientation: bool, ws: dict
) -> np.ndarray:
    """``_cell_histograms`` laid out ``(n_bins, N, hb, wb)``, in the scratch ``ws``."""
    n = imgs.shape[0]
    hb, wb = imgs.shape[1] // cell_size, imgs.shape[2] // cell_size
    rows, cols = hb * cell_size, wb * cell_size
    mag, theta = _gradients(imgs, rows, cols, ws)

    # Orientation bins o0 and o0 + 1 in [0, n_bins + 1] with weights m0, m1;
    # slots n_bins and n_bins + 1 are bins 0 and 1 again (theta may be 2pi).
    slots, npix = n_bins + 2, n * rows * cols
    plan = _scatter_plan(n, rows, cols, cell_size, slots)
    o = theta.reshape(npix)
    o *= np.float32(n_bins / (2 * np.pi))
    mag = mag.reshape(npix)
    if not soft_orientation:
        o += np.float32(0.5)
    lo = np.floor(o, out=_buf(ws, "lo", npix))
    o0 = _buf(ws, "o0", npix, np.int32)
    np.copyto(o0, lo, casting="unsafe")
    mo = _buf(ws, "mo", (1, 2, npix), np.float64)
    if soft_orientation:
        frac = np.subtract(o, lo, out=lo)
        np.multiply(mag, frac, out=frac)
        np.copyto(mo[0, 1], frac)
        np.subtract(mag, frac, out=frac)
        np.copyto(mo[0, 0], frac)
    else:
        np.copyto(mo[0, 0], mag)
        mo[0, 1] = 0.0

    # Scatter chunk by chunk (small outputs stay in cache) and pool rows: cell c
    # sums rows of the cells c-1, c, c+1 weighted by wy, taken as a strided
    # window view of the scatter output.
    row_len = n * wb * slots
    chunk_pix = plan.base.shape[1]
    idx_buf = _buf(ws, "idx", 4 * chunk_pix, np.intp)
    w_buf = _buf(ws, "weights", 4 * chunk_pix, np.float64)
    h = _buf(ws, "h", (hb + 2, 1, row_len), np.float64)  # a cell row of padding each side
    h.fill(0.0)
    h_chunk = _buf(ws, "h_chunk", (plan.cells + 2, 1, row_len), np.float64)
    t_buf = _buf(ws, "scatter", plan.prows * row_len, np.float64)
    for c0 in range(0, hb, plan.cells):
        c1 = min(c0 + plan.cells, hb)
        p0, p1 = c0 * cell_size * n * cols, c1 * cell_size * n * cols
        m = p1 - p0
        idx = np.add(plan.base[:, :m], o0[p0:p1], out=idx_buf[: 4 * m].reshape(4, m))
        weights = np.multiply(plan.wx[:, :, :m], mo[:, :, p0:p1], out=w_buf[: 4 * m].reshape(2, 2, m))
        prows = plan.prows - (plan.cells - (c1 - c0)) * cell_size
        if _FAST_UFUNC_AT:  # into a reused buffer: np.bincount's fresh output page-faults
            t = t_buf[: prows * row_len]
            t.fill(0.0)
            np.add.at(t, idx.reshape(-1), weights.reshape(-1))
        else:
            t = np.bincount(idx.reshape(-1), weights.reshape(-1), minlength=prows * row_len)
        step = t.itemsize * row_len
        windows = np.ndarray(
            (c1 - c0 + 2, plan.wy.shape[1], row_len), t.dtype, t, 0, (cell_size * step, step, t.itemsize)
        )
        h[c0 : c1 + 2] += np.matmul(plan.wy, windows, out=h_chunk[: c1 - c0 + 2])

    # Drop the padding rows, fold slots n_bins, n_bins + 1 into bins 0, 1.
    h = h[1 : hb + 1].reshape(hb, n, wb, slots).transpose(3, 1, 0, 2)
    hist = _buf(ws, "hist", (n_bins, n, hb, wb))
    np.copyto(hist, h[:n_bins], casting="same_kind")
    hist[:2] += h[n_bins:]
    hist *= plan.scale
    return hist


# -------------------------------------------------------------------- normalisation


def _normalise(hist: np.ndarray, n_orients: int, clip: float, cell_size: int, ws: dict) -> np.ndarray:
    """Block-normalise, clip and project cell histograms into fhog channels.

    Args:
        hist: ``(2 * n_orients, N, hb, wb)`` float32 (``_histograms``),
            ``hb, wb >= 2``.
        ws: scratch buffers.

    Returns:
        ``(N, 3 * n_orients + 4, hb, wb)`` float32, C-contiguous, a new array.
    """
    _, n, hb, wb = hist.shape
    no = 3 * n_orients  # orientation channels
    cells = n * hb * wb
    # Orientation features: contrast-sensitive then -insensitive histograms.
    feats = _buf(ws, "feats", (no, cells))
    flat = hist.reshape(2 * n_orients, cells)
    feats[: 2 * n_orients] = flat
    insens = feats[2 * n_orients :]
    np.add(flat[:n_orients], flat[n_orients:], out=insens)

    # 1 / sqrt(energy of each 2x2 block + eps), edge-padded to (hb + 1, wb + 1)
    # so that every cell has 4 blocks.
    energy = np.einsum("ok,ok->k", insens, insens).reshape(n, hb, wb)
    blocks = energy[:, :-1, :-1] + energy[:, 1:, :-1]
    blocks += energy[:, :-1, 1:]
    blocks += energy[:, 1:, 1:]
    blocks += np.float32(1e-4 / 4 / cell_size**4)  # Piotr's eps on this scale
    inv = _buf(ws, "inv", (n, hb + 1, wb + 1))
    core = inv[:, 1:hb, 1:wb]
    np.sqrt(blocks, out=core)
    np.divide(np.float32(1.0), core, out=core)
    inv[:, 0, 1:wb] = core[:, 0]
    inv[:, hb, 1:wb] = core[:, -1]
    inv[:, :, 0] = inv[:, :, 1]
    inv[:, :, wb] = inv[:, :, wb - 1]

    # One new array: the result (for a batch, channel-major scratch first).
    out = np.empty((no + 4, cells), np.float32) if n == 1 else _buf(ws, "out", (no + 4, cells))
    orient = out[:no]
    orient.fill(0.0)
    tmp = _buf(ws, "tmp", (no, cells))
    norm = _buf(ws, "norm", (n, hb, wb))
    # the texture channel of a normalisation sums its clipped sensitive channels
    texture_weights = np.full((1, 2 * n_orients), _TEXTURE_SCALE, np.float32)
    for k, (dr, dc) in enumerate(_BLOCK_OFFSETS):
        np.copyto(norm, inv[:, dr : dr + hb, dc : dc + wb])
        np.multiply(feats, norm.reshape(1, cells), out=tmp)
        cv2.min(tmp, float(clip), dst=tmp)  # np.minimum is 2x slower (NaN checks)
        cv2.add(orient, tmp, dst=orient)
        np.matmul(texture_weights, tmp[: 2 * n_orients], out=out[no + k : no + k + 1])
    orient *= np.float32(0.5)
    out = out.reshape(no + 4, n, hb, wb)
    return out[:, 0][None] if n == 1 else np.ascontiguousarray(out.transpose(1, 0, 2, 3))
