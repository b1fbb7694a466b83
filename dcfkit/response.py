"""Detection: the response map (Eq. 12), its peak and its local maxima.

Filters and samples are Fourier maps of real signals, shape (C, H, W//2+1) complex64.
The response is the circular cross-correlation R(τ) = Σ_c Σ_x h_c(x) s_c(x+τ), i.e.
R = F⁻¹(Σ_c conj(ĥ_c) ⊙ ŝ_c); the paper writes the same operation as a convolution with
the mirrored filter. Offsets τ are circular: index i stands for i - H when i > H // 2.
"""
from __future__ import annotations

import numpy as np
from scipy import ndimage


def response(hf: np.ndarray, sf: np.ndarray, shape: tuple[int, int], fft) -> np.ndarray:
    """Eq. (12): (C, H, Wr) filter and (..., C, H, Wr) samples -> (..., H, W) float32 response."""
    return fft.irfft2(np.einsum("chw,...chw->...hw", hf.conj(), sf), shape).astype(np.float32, copy=False)


def wrap(index, size: int):
    """Circular index -> signed offset in [-(size // 2), (size - 1) // 2]."""
    return (np.asarray(index) + size // 2) % size - size // 2


def subpixel_peak(r: np.ndarray) -> tuple[float, float, float]:
    """Peak of a circular (H, W) map: (dy, dx) signed offset refined by a 1-D parabola per axis, and value."""
    h, w = r.shape
    i, j = np.unravel_index(int(np.argmax(r)), r.shape)
    peak = float(r[i, j])

    def refine(left: float, centre: float, right: float) -> float:
        denom = left - 2.0 * centre + right
        return 0.0 if denom >= 0 else float(np.clip(0.5 * (left - right) / denom, -0.5, 0.5))

    dy = refine(r[(i - 1) % h, j], peak, r[(i + 1) % h, j]) if h > 2 else 0.0
    dx = refine(r[i, (j - 1) % w], peak, r[i, (j + 1) % w]) if w > 2 else 0.0
    return float(wrap(i, h)) + dy, float(wrap(j, w)) + dx, peak


def local_maxima(r: np.ndarray, size: int = 3) -> tuple[np.ndarray, np.ndarray]:
    """Local maxima of a circular (H, W) map: rows, cols of pixels equal to the max of their
    ``size`` x ``size`` (wrapped) neighbourhood and strictly above its minimum (no plateaus
    of a flat map). Sorted by value, highest first."""
    filtered = ndimage.maximum_filter(r, size=size, mode="wrap")
    lowest = ndimage.minimum_filter(r, size=size, mode="wrap")
    rows, cols = np.nonzero((r == filtered) & (r > lowest))
    order = np.argsort(-r[rows, cols], kind="stable")
    return rows[order], cols[order]
