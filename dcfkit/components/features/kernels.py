"""Compiled (numba) per-pixel loops of the features: fhog (:mod:`dcfkit.components.features.fhog`) and
the Color Names cell averages.

Imported on the first extraction, not with the package: importing numba takes about 0.25 s.
Machine code is cached on disk (numba's ``cache=True``: next to this file, or in the user's
cache directory when that is read-only), so only the first process after installation pays
the compilation (about 10 s on this machine); later ones load it (about 0.45 s per process,
mostly numba's own start-up).

Every float32 operation is the one the numpy/OpenCV formulation performed, in the same
order, so results are bit-identical to it (for fhog with the cell size 4: gradients of 8-bit
images are multiples of 1/2, their squared magnitudes are exact in float32, and the bilinear
cell sums are of exact float64 products, whatever their order, before the one rounding to
float32; the Color Names sums follow OpenCV's integer-factor area resize).
"""
from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True, nogil=True)
def gradients(imgs, rows, cols, reverse, gx, gy, mag):  # pragma: no cover - compiled
    """Centred differences of the ``rows x cols`` top-left pixels, negated (Piotr's grad1).

    imgs: (N, H, W, C) uint8 or float32, C = 1 or 3; per pixel the channel with the largest
    magnitude wins, the first on ties (the last with ``reverse``: an RGB image's first channel
    is a BGR array's last). Interior pixels get ``(I[p-1] - I[p+1]) / 2``, image borders the
    one-sided ``I[0] - I[1]``; equal neighbours give +0.0, whose arctan2 is +pi (not -pi) when
    gx < 0. Writes gx, gy, mag: (N, rows, cols) float32.
    """
    n, h, w, channels = imgs.shape
    for i in range(n):
        for y in range(rows):
            y0, y1 = max(y - 1, 0), min(y + 1, h - 1)
            sy = np.float32(0.5) if 0 < y < h - 1 else np.float32(1.0)
            for x in range(cols):
                x0, x1 = max(x - 1, 0), min(x + 1, w - 1)
                sx = np.float32(0.5) if 0 < x < w - 1 else np.float32(1.0)
                c0 = channels - 1 if reverse else 0
                bx = (np.float32(imgs[i, y, x0, c0]) - np.float32(imgs[i, y, x1, c0])) * sx
                by = (np.float32(imgs[i, y0, x, c0]) - np.float32(imgs[i, y1, x, c0])) * sy
                best = bx * bx + by * by  # squares order magnitudes as their roots do
                for k in range(1, channels):
                    c = channels - 1 - k if reverse else k
                    dx = (np.float32(imgs[i, y, x0, c]) - np.float32(imgs[i, y, x1, c])) * sx
                    dy = (np.float32(imgs[i, y0, x, c]) - np.float32(imgs[i, y1, x, c])) * sy
                    m = dx * dx + dy * dy
                    if m > best:
                        best, bx, by = m, dx, dy
                gx[i, y, x] = bx
                gy[i, y, x] = by
                mag[i, y, x] = np.sqrt(best)


@numba.njit(cache=True, nogil=True)
def cell_histograms(mag, theta, cell_size, n_bins, soft, scale, hist):  # pragma: no cover - compiled
    """Scatter pixels into orientation histograms of cells (Piotr's gradHist).

    mag, theta: (N, rows, cols) float32, theta = arctan2(gy, gx) of the negated gradients.
    A pixel's magnitude goes to orientation bin round(n_bins (theta + pi) / 2pi) (or linearly
    to the two nearest with ``soft``) and bilinearly to the 4 nearest cell centres; the sums,
    kept in float64, are rounded to float32, bin n_bins folded onto bin 0 (n_bins + 1 onto
    1), and multiplied by ``scale`` (hb, wb). Writes hist: (n_bins, N, hb, wb) float32.
    """
    n, rows, cols = mag.shape
    hb, wb = rows // cell_size, cols // cell_size
    slots = n_bins + 2
    # pixel p sits at cell coordinate (p + 0.5) / cell_size - 0.5: it feeds the cell left
    # of it with 1 - d and the next with d; cells beyond the border get weight 0
    cy0, wy0, wy1 = _cell_axis(rows, cell_size, hb)
    cx0, wx0, wx1 = _cell_axis(cols, cell_size, wb)
    to_bin = np.float32(n_bins / (2 * np.pi))
    pi = np.float32(np.pi)
    acc = np.zeros((hb + 2, wb + 2, slots))  # cell c at c + 1; cells -1 and hb, wb get weight 0
    for i in range(n):
        acc[:] = 0.0
        for y in range(rows):
            r0, a0, a1 = cy0[y] + 1, wy0[y], wy1[y]
            for x in range(cols):
                o = (theta[i, y, x] + pi) * to_bin
                m = mag[i, y, x]
                if soft:
                    lo = np.floor(o)
                    m1 = m * (o - lo)
                    m0 = m - m1
                else:
                    lo = np.floor(o + np.float32(0.5))
                    m1 = np.float32(0.0)
                    m0 = m
                b = int(lo)
                c0, b0, b1 = cx0[x] + 1, wx0[x], wx1[x]
                for r, a in ((r0, a0), (r0 + 1, a1)):
                    v0, v1 = a * float(m0), a * float(m1)
                    acc[r, c0, b] += b0 * v0
                    acc[r, c0 + 1, b] += b1 * v0
                    if soft:
                        acc[r, c0, b + 1] += b0 * v1
                        acc[r, c0 + 1, b + 1] += b1 * v1
        for k in range(n_bins):
            for r in range(hb):
                for c in range(wb):
                    v = np.float32(acc[r + 1, c + 1, k])
                    if k < 2:  # numpy's float32 += float64: the sum in float64, then rounded
                        v = np.float32(float(v) + acc[r + 1, c + 1, n_bins + k])
                    hist[k, i, r, c] = v * scale[r, c]


@numba.njit(cache=True, nogil=True)
def normalise(hist, clip, eps, orient, clipped):  # pragma: no cover - compiled
    """Block normalisation and clipping of fhog (see ``fhog._normalise``).

    hist: (2n, N, hb, wb) float32 contrast-sensitive histograms. Per cell, the
    contrast-insensitive histogram is the sum of opposite bins; ``1 / sqrt(energy + eps)`` of
    each of the 4 2x2-cell blocks around the cell (edge-replicated at the borders) scales the
    3n orientation channels, which are clipped at ``clip``. Writes orient: (3n, N, hb, wb)
    float32, half the sum of the 4 clipped normalisations; clipped: (4, 2n, N, hb, wb) the
    clipped sensitive channels per normalisation (the texture channels sum them).

    Not split: one compiled pass whose float32 operations keep the order of the vectorised
    ``fhog._normalise`` it replaces bit for bit; its stages share the per-cell buffers.
    """
    n2, n, hb, wb = hist.shape
    no = n2 // 2
    cells = n * hb * wb
    clip32 = np.float32(clip)
    half = np.float32(0.5)
    energy = np.empty((hb, wb), np.float32)
    inv = np.empty((hb + 1, wb + 1), np.float32)
    norm = np.empty((4, n, hb, wb), np.float32)  # the 4 normalisers of every cell
    for i in range(n):
        for r in range(hb):
            for c in range(wb):
                e = np.float32(0.0)
                for o in range(no):
                    v = hist[o, i, r, c] + hist[o + no, i, r, c]
                    e = e + v * v
                energy[r, c] = e
        for r in range(hb - 1):
            for c in range(wb - 1):
                b = energy[r, c] + energy[r + 1, c]
                b = b + energy[r, c + 1]
                b = b + energy[r + 1, c + 1]
                b = b + eps
                inv[r + 1, c + 1] = np.float32(1.0) / np.sqrt(b)
        for c in range(1, wb):
            inv[0, c] = inv[1, c]
            inv[hb, c] = inv[hb - 1, c]
        for r in range(hb + 1):
            inv[r, 0] = inv[r, 1]
            inv[r, wb] = inv[r, wb - 1]
        for k in range(4):  # blocks below-right, above-right, below-left, above-left
            dr, dc = 1 - k % 2, 1 - k // 2
            for r in range(hb):
                for c in range(wb):
                    norm[k, i, r, c] = inv[r + dr, c + dc]
    # channel by channel over all cells of all images: long contiguous loops LLVM vectorises
    h = hist.reshape(n2, cells)
    nk = norm.reshape(4, cells)
    out = orient.reshape(3 * no, cells)
    kept = clipped.reshape(4, n2, cells)
    feat = np.empty(cells, np.float32)
    acc = np.empty(cells, np.float32)
    for o in range(3 * no):
        if o < n2:
            feat[:] = h[o]
        else:
            for q in range(cells):
                feat[q] = h[o - n2, q] + h[o - no, q]
        for k in range(4):
            for q in range(cells):
                t = min(feat[q] * nk[k, q], clip32)
                acc[q] = t if k == 0 else acc[q] + t
                if o < n2:
                    kept[k, o, q] = t
        for q in range(cells):
            out[o, q] = acc[q] * half


@numba.njit(cache=True, nogil=True)
def _cell_axis(length, cell_size, cells):  # pragma: no cover - compiled
    """Per pixel: the cell left of it (-1 before the first centre) and the two weights."""
    left = np.empty(length, np.int64)
    w_left = np.empty(length)
    w_right = np.empty(length)
    for p in range(length):
        t = (p + 0.5) / cell_size - 0.5
        f = np.floor(t)
        d = t - f
        left[p] = int(f)
        w_left[p] = 1.0 - d if f >= 0 else 0.0
        w_right[p] = d if f + 1 < cells else 0.0
    return left, w_left, w_right


@numba.njit(cache=True, nogil=True)
def colornames_cells(bgr, table, cell_size, out):  # pragma: no cover - compiled
    """Color Names averaged over each cell. bgr: (H, W, 3) uint8; table: (32768, D) float32
    indexed by R/8 + 32 G/8 + 1024 B/8; writes out: (D, H // cell_size, W // cell_size).

    Sums as OpenCV's integer-factor area resize does: each cell row left to right, then the
    rows top to bottom, times 1 / cell_size².
    """
    hb, wb = bgr.shape[0] // cell_size, bgr.shape[1] // cell_size  # whole cells only
    d = table.shape[1]
    scale = np.float32(1.0 / (cell_size * cell_size))
    row = np.empty(d, np.float32)
    total = np.empty(d, np.float32)
    for r in range(hb):
        for c in range(wb):
            total[:] = 0.0
            for sy in range(cell_size):
                y = r * cell_size + sy
                for sx in range(cell_size):
                    x = c * cell_size + sx
                    b, g, r8 = np.int64(bgr[y, x, 0]), np.int64(bgr[y, x, 1]), np.int64(bgr[y, x, 2])
                    idx = (r8 >> 3) | ((g >> 3) << 5) | ((b >> 3) << 10)
                    for k in range(d):
                        row[k] = table[idx, k] if sx == 0 else row[k] + table[idx, k]
                for k in range(d):
                    total[k] = total[k] + row[k]
            for k in range(d):
                out[k, r, c] = total[k] * scale


@numba.njit(cache=True, nogil=True)
def texture(clipped, weight, out):  # pragma: no cover - compiled
    """fhog's texture channels: out[k] = Σ_o clipped[k, o] · weight over the 2n clipped sensitive
    channels of normalisation k, added in channel order. clipped (4, 2n, cells), out (4, cells)."""
    blocks, n2, cells = clipped.shape
    for k in range(blocks):
        for p in range(cells):
            t = clipped[k, 0, p] * weight
            for o in range(1, n2):
                t = t + clipped[k, o, p] * weight
            out[k, p] = t
