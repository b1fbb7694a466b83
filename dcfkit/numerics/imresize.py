"""MATLAB's ``imresize`` with its default bicubic kernel, antialiased when shrinking: CSR-DCF's
``get_csr_features`` resizes its patch, and each gray and Color Names map to the cell grid, so.

Per axis (MATLAB's ``contributions``): output pixel x (1-based) reads u = x / s + (1 - 1/s) / 2,
s = out / in, from the pixels within half the kernel's width of u, weighted by Keys' cubic
(a = -0.5) scaled by s when s < 1 (width 4 / s), the weights normalised to sum to 1 and the
pixels beyond the border mirrored. The axis that shrinks most goes first; a uint8 image is
rounded (halves up) and saturated after each axis, as MATLAB returns each pass in its class.
"""
from __future__ import annotations

import functools

import numpy as np


def _cubic(x: np.ndarray) -> np.ndarray:
    a = np.abs(x)
    a2, a3 = a * a, a * a * a
    return (1.5 * a3 - 2.5 * a2 + 1) * (a <= 1) + (-0.5 * a3 + 2.5 * a2 - 4 * a + 2) * ((a > 1) & (a <= 2))


def _triangle(x: np.ndarray) -> np.ndarray:
    return (x + 1) * ((-1 <= x) & (x < 0)) + (1 - x) * ((0 <= x) & (x <= 1))


@functools.lru_cache(maxsize=256)
def contributions(n_in: int, n_out: int, bilinear: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """(n_out, P) 0-based source pixels and their weights of each output pixel along one axis:
    bicubic, antialiased when shrinking; or ``bilinear`` without antialiasing."""
    scale = n_out / n_in
    shrink = scale < 1 and not bilinear
    kernel = _triangle if bilinear else _cubic
    width = 2.0 if bilinear else 4.0 / scale if shrink else 4.0
    u = np.arange(1, n_out + 1) / scale + 0.5 * (1 - 1 / scale)
    left = np.floor(u - width / 2)
    index = left[:, None] + np.arange(int(np.ceil(width)) + 2)[None, :]
    distance = u[:, None] - index
    weights = scale * kernel(scale * distance) if shrink else kernel(distance)
    weights /= weights.sum(axis=1, keepdims=True)
    mirror = np.concatenate([np.arange(n_in), np.arange(n_in)[::-1]])  # 1..n, n..1 of MATLAB, 0-based
    index = mirror[np.mod(index - 1, 2 * n_in).astype(np.int64)]
    used = np.any(weights != 0, axis=0)
    index, weights = index[:, used], weights[:, used]
    index.setflags(write=False)
    weights.setflags(write=False)
    return index, weights


def _along(x: np.ndarray, axis: int, n_out: int, bilinear: bool) -> np.ndarray:
    """One axis resized, in float64, the taps summed in their order (as imresizemex)."""
    from dcfkit.numerics import resize_kernels  # lazy: numba, compiled on first use

    index, weights = contributions(x.shape[axis], n_out, bilinear)
    a = np.ascontiguousarray(x.reshape(x.shape[:2] + (-1,)))
    if axis == 0:
        out = np.empty((n_out, a.shape[1] * a.shape[2]))
        resize_kernels.rows(a.reshape(a.shape[0], -1), index, weights, out)
    else:
        out = np.empty((a.shape[0], n_out, a.shape[2]))
        resize_kernels.columns(a, index, weights, out)
    return out.reshape((n_out, x.shape[1]) + x.shape[2:] if axis == 0 else (x.shape[0], n_out) + x.shape[2:])


def imresize(x: np.ndarray, out: tuple[int, int], bilinear: bool = False) -> np.ndarray:
    """``imresize(x, out)`` of an (H, W[, C]) uint8 or float array to ``out`` (h, w): the same
    dtype (uint8 rounded and saturated after each axis; float32 or float64 as given).
    ``bilinear``: ``imresize(x, out, 'bilinear', 'AntiAliasing', false)``."""
    scales = [out[0] / x.shape[0], out[1] / x.shape[1]]
    result = x
    for axis in sorted(range(2), key=lambda a: scales[a]):  # MATLAB's order: the smaller scale first
        if result.shape[axis] == out[axis] and scales[axis] == 1:
            continue
        result = _along(result, axis, int(out[axis]), bilinear)
        if x.dtype == np.uint8:
            result = np.clip(np.floor(result + 0.5), 0, 255).astype(np.uint8)
        else:
            result = result.astype(x.dtype, copy=False)
    return result if result is not x else x.copy()
