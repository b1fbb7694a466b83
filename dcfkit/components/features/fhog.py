"""Felzenszwalb HOG ("fhog") as computed by Piotr Dollar's toolbox.

STRCF, BACF and DR2Track extract hand-crafted features through ``get_fhog``,
which calls Piotr's ``fhog(single(im), cell_size, 9, 0.2)`` and keeps the first
31 of its 32 channels.  This module reimplements that descriptor (Felzenszwalb
et al., "Object Detection with Discriminatively Trained Part-Based Models", PAMI
2010, Sec. 6) with numpy and compiled loops (:mod:`dcfkit.components.features.kernels`):

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

The loops are compiled (:mod:`.kernels`); arctan2 and the texture sums stay numpy's, whose
last bits decide orientation bins at their boundaries.
"""

from __future__ import annotations

import dataclasses
import threading
from collections import OrderedDict
from functools import lru_cache

import numpy as np

from dcfkit.components.features.base import Feature
from dcfkit.params import param

__all__ = ["ARITHMETICS", "fhog", "fhog_channels"]

# exact arithmetic, or gradientMex's estimates: the same on every machine, or this processor's
ARITHMETICS = ("exact", "sse", "sse_cpu")

_TEXTURE_SCALE = 0.2357  # Piotr's constant for the 4 texture channels


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
    channel_order: str = "bgr",
    arithmetic: str = "exact",
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
        channel_order: the order of a colour image's channels, which decides
            which channel's gradient a pixel takes when two are equally strong
            (the first): 'bgr' (OpenCV's images) or 'rgb' (MATLAB's, which makes
            a BGR array's red channel win, as in the authors' trackers).
        arithmetic: 'exact' (square roots and arctan), or the estimates and
            lookup table of Piotr's compiled gradientMex, which the authors'
            MATLAB runs (:mod:`dcfkit.components.features.fhog_sse`; ``soft_orientation``
            not available): 'sse' computes them the same way on every
            machine, 'sse_cpu' takes this processor's (x86 only).

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
    if channel_order not in ("bgr", "rgb"):
        raise ValueError(f"fhog: channel_order must be 'bgr' or 'rgb', got {channel_order!r}")
    if arithmetic not in ARITHMETICS:
        raise ValueError(f"fhog: arithmetic must be one of {', '.join(ARITHMETICS)}, got {arithmetic!r}")
    imgs = _as_stack(image, batch, cell_size)
    if arithmetic != "exact":
        if soft_orientation:
            raise ValueError(f"fhog: arithmetic {arithmetic!r} (Piotr's gradientMex) bins orientations hard; "
                             "soft_orientation is not available with it")
        from dcfkit.components.features.fhog_sse import fhog_sse  # lazy: numba, compiled on first use

        out = fhog_sse(imgs, cell_size, n_orients, clip, channel_order == "rgb", arithmetic)
        return out if batch else out[0]
    if imgs.shape[0] == 0:
        hb, wb = imgs.shape[1] // cell_size, imgs.shape[2] // cell_size
        return np.zeros((0, fhog_channels(n_orients), hb, wb), np.float32)
    ws = _workspace((imgs.shape, imgs.dtype.char, cell_size, n_orients))
    hist = _histograms(imgs, cell_size, 2 * n_orients, soft_orientation, ws, channel_order == "rgb")
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


# ----------------------------------------------------------------------- histograms


@lru_cache(maxsize=16)
def _border_scale(hb: int, wb: int, cell_size: int) -> np.ndarray:
    """(hb, wb) float32: ``1 / cell_size**2`` times ``8/7`` per image border a cell touches."""
    edge_r = np.ones(hb)
    edge_r[[0, -1]] = 8.0 / 7.0
    edge_c = np.ones(wb)
    edge_c[[0, -1]] = 8.0 / 7.0
    scale = (np.outer(edge_r, edge_c) / cell_size**2).astype(np.float32)
    scale.setflags(write=False)
    return scale


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
    imgs: np.ndarray, cell_size: int, n_bins: int, soft_orientation: bool, ws: dict, reverse: bool = False
) -> np.ndarray:
    """``_cell_histograms`` laid out ``(n_bins, N, hb, wb)``, in the scratch ``ws``."""
    from dcfkit.components.features import kernels  # numba: imported and compiled (or loaded from disk) on first use

    n = imgs.shape[0]
    hb, wb = imgs.shape[1] // cell_size, imgs.shape[2] // cell_size
    rows, cols = hb * cell_size, wb * cell_size
    if imgs.ndim == 3:
        imgs = imgs[..., None]
    gx, gy, mag = (_buf(ws, name, (n, rows, cols)) for name in ("gx", "gy", "mag"))
    kernels.gradients(np.ascontiguousarray(imgs), rows, cols, reverse, gx, gy, mag)
    # numpy's arctan2 (its SIMD path), not the compiled loop's libm one: bins near a
    # boundary depend on the last bit
    theta = np.arctan2(gy, gx, out=_buf(ws, "theta", (n, rows, cols)))
    hist = _buf(ws, "hist", (n_bins, n, hb, wb))
    kernels.cell_histograms(mag, theta, cell_size, n_bins, soft_orientation,
                            _border_scale(hb, wb, cell_size), hist)
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
    from dcfkit.components.features import kernels  # lazy: numba, compiled on first use

    _, n, hb, wb = hist.shape
    no = 3 * n_orients  # orientation channels
    cells = n * hb * wb
    # One new array: the result (for a batch, channel-major scratch first).
    out = np.empty((no + 4, cells), np.float32) if n == 1 else _buf(ws, "out", (no + 4, cells))
    clipped = _buf(ws, "clipped", (4, 2 * n_orients, cells))
    eps = np.float32(1e-4 / 4 / cell_size**4)  # Piotr's eps on this scale
    kernels.normalise(hist, clip, eps, out[:no].reshape(no, n, hb, wb),
                      clipped.reshape(4, 2 * n_orients, n, hb, wb))
    # in channel order, not by a BLAS matmul, whose order depends on the processor
    kernels.texture(clipped, np.float32(_TEXTURE_SCALE), out[no:])
    out = out.reshape(no + 4, n, hb, wb)
    return out[:, 0][None] if n == 1 else np.ascontiguousarray(out.transpose(1, 0, 2, 3))


MAX_ORIENTS = 36  # fhog's bins of 5 degrees


MIN_CLIP = 1e-6


class FHOG(Feature):
    """Felzenszwalb HOG: 18 signed + 9 unsigned orientation bins + 4 texture channels."""

    name = "fhog"

    @dataclasses.dataclass(frozen=True)
    class Params:
        # at most MAX_ORIENTS: 3 channels each, the size of the maps and the solver's time; clip at least
        # MIN_CLIP: a smaller one keeps only which bins are empty, or rounds to float32's 0
        n_orients: int = param(9, "unsigned orientation bins (signed ones: twice as many)", ge=2, le=MAX_ORIENTS)
        clip: float = param(0.2, "truncation of the normalised histograms", ge=MIN_CLIP, le=1)
        soft_orientation: bool = param(False, "split each gradient between the two nearest orientation bins "
                                              "(false: nearest bin only, as Piotr's fhog used by STRCF/BACF)")
        channel_order: str = param("bgr", "which colour channel's gradient a pixel takes when two are equally "
                                   "strong: the first of 'bgr' (OpenCV's order) or of 'rgb' (MATLAB's: the "
                                   "authors' code)", choices=("bgr", "rgb"))
        arithmetic: str = param("exact", "'exact' square roots and arctan, or the estimates and acos table of "
                                "Piotr's compiled gradientMex that the authors' MATLAB runs: 'sse' the same on every "
                                "machine, 'sse_cpu' this processor's (x86 only)", choices=ARITHMETICS)
        output: str = param("all", "channels kept: 'all', or 'signed' the 2 n_orients contrast-sensitive ones only "
                            "(CSR-DCF's get_csr_features)", choices=("all", "signed"))

        def validate(self):
            """gradientMex's arithmetic only with soft_orientation false."""
            if self.arithmetic != "exact" and self.soft_orientation:
                return (f"arithmetic {self.arithmetic!r} (Piotr's gradientMex) bins orientations hard: "
                        "set soft_orientation false")

    def channels(self) -> int:
        return (2 if self.params.output == "signed" else 3) * self.params.n_orients + 4 * (self.params.output == "all")

    def extract(self, patch, cell_size):
        p = self.params
        out = fhog(patch, cell_size=cell_size, n_orients=p.n_orients, clip=p.clip, soft_orientation=p.soft_orientation,
                   channel_order=p.channel_order, arithmetic=p.arithmetic)
        return out if p.output == "all" else out[:2 * p.n_orients]
