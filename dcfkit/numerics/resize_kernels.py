"""Compiled (numba) tap sums of MATLAB's ``imresize`` (:mod:`dcfkit.numerics.imresize`).

numpy summed the taps as whole-array passes, one gathered copy of the image per tap: a large
template shrunk by 3 has 14 taps, and CSR-DCF's resizes took over half its frame. Here each
output pixel sums its taps in the same order, in float64, with the same two roundings per tap
(a product, then a sum: numba contracts nothing into a fused multiply-add without fastmath),
so results are bit-identical. Loaded on first use (numba's import costs 0.25 s), cached on disk.
"""
from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True, nogil=True)
def rows(a, index, weights, out):  # pragma: no cover - compiled
    """out[i, k] = Σ_j weights[i, j] a[index[i, j], k], j in order: the first axis resized, a
    row at a time. a (H, K) uint8, float32 or float64 (K: the columns times the channels);
    index, weights (n_out, P); out (n_out, K) float64."""
    k = a.shape[1]
    for i in range(index.shape[0]):
        w, src = weights[i, 0], index[i, 0]
        for x in range(k):
            out[i, x] = w * np.float64(a[src, x])
        for j in range(1, index.shape[1]):
            w, src = weights[i, j], index[i, j]
            for x in range(k):
                out[i, x] += w * np.float64(a[src, x])


@numba.njit(cache=True, nogil=True)
def columns(a, index, weights, out):  # pragma: no cover - compiled
    """out[y, i, c] = Σ_j weights[i, j] a[y, index[i, j], c], j in order: the second axis
    resized. a (H, W, C); out (H, n_out, C) float64."""
    h, _, channels = a.shape
    for y in range(h):
        for i in range(index.shape[0]):
            for c in range(channels):
                acc = weights[i, 0] * np.float64(a[y, index[i, 0], c])
                for j in range(1, index.shape[1]):
                    acc += weights[i, j] * np.float64(a[y, index[i, j], c])
                out[y, i, c] = acc
