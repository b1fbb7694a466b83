"""fhog in the arithmetic of Piotr's ``gradientMex`` (toolbox 3.30), which the authors' MATLAB
trackers compile: its SSE estimates and its lookup table, not exact square roots and arctan.

:mod:`dcfkit.components.features.fhog` computes the descriptor exactly. Piotr's code instead takes the
gradient magnitude as ``rcp(min(rsqrt(M²), 1e10))`` (the SSE reciprocal and reciprocal-
square-root estimates, ~12 bits) and the orientation from a 20,020-entry ``acos`` table
indexed by ``trunc(10000 gx rsqrt(M²))``; a pixel near a bin boundary then falls into the
other bin. Here every operation of ``gradMag``, ``gradHist`` (hard orientation bins, bilinear
cell weights, 8/7 on the border), ``hogNormMatrix`` and ``hogChannels`` is repeated in
float32 in the same order.

The estimates are specified only by their error bound, and each processor family has its own:
on an AMD Zen 5 half of all inputs get other values than on the machine that made dcfkit's
first reference runs, and one pixel moving to another bin can move a box. Arithmetic 'sse'
therefore computes them by table (:mod:`dcfkit.components.features.sse_estimates`) and takes a correctly
rounded acos table: the same features on every machine. 'sse_cpu' runs this processor's own
instructions and the C library's ``acosf``, as a MATLAB run compiled on this machine does.
"""
from __future__ import annotations

import ctypes
import ctypes.util
import functools
import math

import numba
import numpy as np

from dcfkit.components.features import sse_estimates

_PI = np.float32(3.14159265)  # Piotr's PI, a float
_TABLE_N, _TABLE_B = 10000, 10


@functools.lru_cache(maxsize=2)
def acos_table(c_library: bool = False) -> np.ndarray:
    """Piotr's ``acosTable``: a[i + 10010] = acos(i / 10000f) for i in [-10000, 10000), π below,
    0 above, capped at π - 1e-6 up to i = 1000. float32 (20020,). The values are correctly
    rounded, or with ``c_library`` the C library's ``acosf``, as the mex file compiled on this
    machine takes them (glibc 2.36's differs from the correctly rounded value on 1,583 of them)."""
    n, b = _TABLE_N, _TABLE_B
    i = np.arange(-n - b, n + b)
    x = (i[b:b + 2 * n].astype(np.float32) / np.float32(n)).astype(np.float32)
    libm = ctypes.util.find_library("m") if c_library else None
    if libm:
        acosf = ctypes.CDLL(libm).acosf
        acosf.restype, acosf.argtypes = ctypes.c_float, [ctypes.c_float]
        core = np.array([acosf(float(v)) for v in x], np.float32)
    else:  # a double acos within an ulp rounds to the nearest float
        core = np.array([math.acos(float(v)) for v in x]).astype(np.float32)
    table = np.concatenate([np.full(b, _PI, np.float32), core, np.zeros(b, np.float32)])
    cap = np.float32(_PI - np.float32(1e-6))
    head = i < n // 10
    table[head & (table > cap)] = cap
    table.setflags(write=False)
    return table


@numba.njit(cache=True, nogil=True)
def _strongest_gradient(img, reverse, m2, gx, gy):  # pragma: no cover - compiled
    """gradMag's per-pixel gradient of (H, W, C) float32: the strongest channel's (first on
    ties, in RGB order when ``reverse`` for a BGR image) squared magnitude and components."""
    h, w, channels = img.shape
    half, one = np.float32(0.5), np.float32(1.0)
    for x in range(w):
        xp, xn, rx = x - 1, x + 1, half
        if x == 0:
            xp, rx = 0, one
        elif x == w - 1:
            xn, rx = w - 1, one
        for y in range(h):
            yp, yn, ry = y - 1, y + 1, half
            if y == 0:
                yp, ry = 0, one
            elif y == h - 1:
                yn, ry = h - 1, one
            best, bx, by = np.float32(0), np.float32(0), np.float32(0)
            for k in range(channels):
                c = channels - 1 - k if reverse else k
                dx = (img[y, xn, c] - img[y, xp, c]) * rx
                dy = (img[yn, x, c] - img[yp, x, c]) * ry
                d2 = dx * dx + dy * dy
                if k == 0 or d2 > best:
                    best, bx, by = d2, dx, dy
            m2[y, x], gx[y, x], gy[y, x] = best, bx, by


@numba.njit(inline="always", nogil=True)
def _orientation(gx, gy, r, table):  # pragma: no cover - compiled
    """gradMag's orientation in [0, 2π): the acos table at trunc(10000 gx r), r the rsqrt estimate."""
    cosine = (gx * r) * np.float32(10000.0)
    if gy < 0:
        cosine = -cosine
    o = table[int(cosine) + 10010]
    if gy < 0:
        o = o + np.float32(3.14159265)
    return o


@numba.njit(cache=True, nogil=True)
def _by_table(m2, gx, gy, table, rcp_table, rsqrt_table, mag, orient):  # pragma: no cover - compiled
    """Magnitude rcp(min(rsqrt(M²), 1e10)) and orientation per pixel, the estimates by table."""
    h, w = m2.shape
    for y in range(h):
        for x in range(w):
            r = min(sse_estimates.rsqrt_one(m2[y, x], rsqrt_table), np.float32(1e10))
            mag[y, x] = sse_estimates.rcp_one(r, rcp_table)
            orient[y, x] = _orientation(gx[y, x], gy[y, x], r, table)


@numba.njit(cache=True, nogil=True)
def _orientations(gx, gy, r, table, orient):  # pragma: no cover - compiled
    h, w = gx.shape
    for y in range(h):
        for x in range(w):
            orient[y, x] = _orientation(gx[y, x], gy[y, x], r[y, x], table)


def _grad_mag(img, reverse, arithmetic, mag, orient):
    """gradMag(I, 0, full=1): the magnitude estimate ``rcp(min(rsqrt(M²), 1e10))`` and the
    orientation from the acos table at ``trunc(10000 gx rsqrt(M²))``."""
    m2, gx, gy = (np.empty_like(mag) for _ in range(3))
    _strongest_gradient(img, reverse, m2, gx, gy)
    if arithmetic == "sse_cpu":  # the processor's instructions, compiled apart (x86 only)
        r = np.minimum(sse_estimates.cpu_rsqrt(m2), np.float32(1e10))
        mag[...] = sse_estimates.cpu_rcp(r)
        _orientations(gx, gy, r, acos_table(c_library=True), orient)
    else:
        _by_table(m2, gx, gy, acos_table(), *sse_estimates.estimate_tables(), mag, orient)


@numba.njit(cache=True, nogil=True)
def _grad_hist(mag, orient, cell, n_bins, hist):  # pragma: no cover - compiled
    """gradHist with softBin = -1 (nearest orientation bin, bilinear over cells): hist is
    (n_bins, wb, hb) float32, zeroed, summed pixel column by pixel column as Piotr's.

    Not split: one compiled pass over the pixels, statement for statement the reference's loop (its
    float32 rounding included); calls between numba functions would break that correspondence."""
    h, w = mag.shape
    hb, wb = h // cell, w // cell
    h0, w0 = hb * cell, wb * cell
    s = np.float32(cell)
    s_inv = np.float32(1.0) / s
    s_inv2 = np.float32(1.0) / s / s
    o_mult = np.float32(n_bins) / (np.float32(2.0) * np.float32(3.14159265))
    init = (np.float32(0.0) + np.float32(0.5)) * s_inv - np.float32(0.5)
    xb = init
    bins = np.empty(h0, np.int64)
    m0 = np.empty(h0, np.float32)
    one = np.float32(1.0)
    for x in range(w0):
        for y in range(h0):
            b = int(orient[y, x] * o_mult + np.float32(0.5))
            bins[y] = 0 if b >= n_bins else b
            m0[y] = mag[y, x] * s_inv2
        has_lf = xb >= 0
        xb0 = int(xb) if has_lf else -1
        has_rt = xb0 < wb - 1
        xd = xb - np.float32(xb0)
        xb = xb + s_inv
        yb = init
        y = 0
        while y < cell // 2:  # leading rows: no cell above
            yb0 = -1
            yd = yb - np.float32(yb0)
            yb = yb + s_inv
            xyd = xd * yd
            if has_lf:
                hist[bins[y], xb0, 0] += (yd - xyd) * m0[y]
            if has_rt:
                hist[bins[y], xb0 + 1, 0] += xyd * m0[y]
            y += 1
        while True:  # rows with a cell above and below
            yb0 = int(yb)
            if yb0 >= hb - 1:
                break
            yd = yb - np.float32(yb0)
            yb = yb + s_inv
            xyd = xd * yd
            if has_lf:
                hist[bins[y], xb0, yb0] += (((one - xd) - yd) + xyd) * m0[y]
                hist[bins[y], xb0, yb0 + 1] += (yd - xyd) * m0[y]
            if has_rt:
                hist[bins[y], xb0 + 1, yb0] += (xd - xyd) * m0[y]
                hist[bins[y], xb0 + 1, yb0 + 1] += xyd * m0[y]
            y += 1
        while y < h0:  # final rows: no cell below
            yb0 = int(yb)
            yd = yb - np.float32(yb0)
            yb = yb + s_inv
            xyd = xd * yd
            if has_lf:
                hist[bins[y], xb0, yb0] += (((one - xd) - yd) + xyd) * m0[y]
            if has_rt:
                hist[bins[y], xb0 + 1, yb0] += (xd - xyd) * m0[y]
            y += 1
    border = np.float32(8.0) / np.float32(7.0)
    for o in range(n_bins):
        for yy in range(hb):
            hist[o, 0, yy] *= border
        for xx in range(wb):
            hist[o, xx, 0] *= border
        for yy in range(hb):
            hist[o, wb - 1, yy] *= border
        for xx in range(wb):
            hist[o, xx, hb - 1] *= border


@numba.njit(cache=True, nogil=True)
def _fhog_channels(r1, n_orients, cell, clip, out):  # pragma: no cover - compiled
    """hogNormMatrix and hogChannels of fhog: r1 (2n, wb, hb) -> out (3n + 4, hb, wb).

    Not split: one compiled pass over the pixels, statement for statement the reference's loop (its
    float32 rounding included); calls between numba functions would break that correspondence."""
    n2, wb, hb = r1.shape
    r2 = np.empty((n_orients, wb, hb), np.float32)
    for o in range(n_orients):
        for x in range(wb):
            for y in range(hb):
                r2[o, x, y] = r1[o, x, y] + r1[o + n_orients, x, y]
    c = np.float32(cell)
    eps = np.float32(1e-4) / np.float32(4) / c / c / c / c
    energy = np.zeros((wb + 1, hb + 1), np.float32)  # N1 = N + hb1 + 1: cell (x, y) at [x, y]
    for o in range(n_orients):
        for x in range(wb):
            for y in range(hb):
                energy[x, y] += r2[o, x, y] * r2[o, x, y]
    norm = np.zeros((wb + 1, hb + 1), np.float32)  # N, padded by one cell on each side
    for x in range(wb - 1):
        for y in range(hb - 1):
            total = (((energy[x, y] + energy[x, y + 1]) + energy[x + 1, y]) + energy[x + 1, y + 1]) + eps
            norm[x + 1, y + 1] = np.float32(1.0) / np.sqrt(total)
    hb1, wb1 = hb + 1, wb + 1
    norm[0, 0] = norm[1, 1]
    for y in range(hb1):
        norm[0, y] = norm[1, y]
    norm[0, hb1 - 1] = norm[1, hb1 - 2]
    norm[wb1 - 1, 0] = norm[wb1 - 2, 1]
    for y in range(hb1):
        norm[wb1 - 1, y] = norm[wb1 - 2, y]
    norm[wb1 - 1, hb1 - 1] = norm[wb1 - 2, hb1 - 2]
    for x in range(wb1):
        norm[x, 0] = norm[x, 1]
    for x in range(wb1):
        norm[x, hb1 - 1] = norm[x, hb1 - 2]
    out[:] = 0
    half, tex = np.float32(0.5), np.float32(0.2357)
    # N1[y - blk] for blk = 0, 1, hb1, hb1 + 1 of the padded column-major N: cell (x, y)'s four
    # blocks are norm[x + 1, y + 1], norm[x + 1, y], norm[x, y + 1], norm[x, y]
    for o in range(n2):
        for x in range(wb):
            for y in range(hb):
                v = r1[o, x, y]
                for t in (v * norm[x + 1, y + 1], v * norm[x + 1, y], v * norm[x, y + 1], v * norm[x, y]):
                    out[o, y, x] += min(t, clip) * half
    for o in range(n_orients):
        for x in range(wb):
            for y in range(hb):
                v = r2[o, x, y]
                for t in (v * norm[x + 1, y + 1], v * norm[x + 1, y], v * norm[x, y + 1], v * norm[x, y]):
                    out[n2 + o, y, x] += min(t, clip) * half
    base = n2 + n_orients
    for o in range(n2):
        for x in range(wb):
            for y in range(hb):
                v = r1[o, x, y]
                k = 0
                for t in (v * norm[x + 1, y + 1], v * norm[x + 1, y], v * norm[x, y + 1], v * norm[x, y]):
                    out[base + k, y, x] += min(t, clip) * tex
                    k += 1


def fhog_sse(imgs: np.ndarray, cell_size: int, n_orients: int, clip: float, reverse: bool,
             arithmetic: str = "sse") -> np.ndarray:
    """(N, H, W[, 3]) images -> (N, 3 n_orients + 4, H // cell, W // cell) float32, as gradientMex's
    ``fhog(single(I), cell_size, n_orients, clip)`` without its zero last channel; ``arithmetic``
    'sse' (estimates and acos the same everywhere) or 'sse_cpu' (this machine's)."""
    n = imgs.shape[0]
    if imgs.ndim == 3:
        imgs = imgs[..., None]
    h, w = imgs.shape[1:3]
    hb, wb = h // cell_size, w // cell_size
    out = np.empty((n, 3 * n_orients + 4, hb, wb), np.float32)
    mag = np.empty((h, w), np.float32)
    orient = np.empty((h, w), np.float32)
    hist = np.empty((2 * n_orients, wb, hb), np.float32)
    for i in range(n):
        _grad_mag(np.ascontiguousarray(imgs[i], np.float32), reverse, arithmetic, mag, orient)
        hist[:] = 0
        _grad_hist(mag, orient, cell_size, 2 * n_orients, hist)
        _fhog_channels(hist, n_orients, cell_size, np.float32(clip), out[i])
    return out
