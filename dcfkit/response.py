"""Detection: the response map (Eq. 12), its peak and its local maxima.

Filters and samples are Fourier maps of real signals, shape (C, H, W//2+1) complex64.
The response is the circular cross-correlation R(τ) = Σ_c Σ_x h_c(x) s_c(x+τ), i.e.
R = F⁻¹(Σ_c conj(ĥ_c) ⊙ ŝ_c); the paper writes the same operation as a convolution with
the mirrored filter. Offsets τ are circular: index i stands for i - H when i > H // 2.
"""
from __future__ import annotations

import cv2
import numpy as np


def response(hf: np.ndarray, sf: np.ndarray, shape: tuple[int, int], fft) -> np.ndarray:
    """Eq. (12): (C, H, Wr) filter and (..., C, H, Wr) samples -> (..., H, W) float32 response."""
    return fft.irfft2(np.einsum("chw,...chw->...hw", hf.conj(), sf), shape).astype(np.float32, copy=False)


def wrap(index, size: int):
    """Circular index -> signed offset in [-(size // 2), (size - 1) // 2]."""
    return (np.asarray(index) + size // 2) % size - size // 2


def subpixel_peak(r: np.ndarray, iterations: int = 5) -> tuple[float, float, float]:
    """Peak of a circular (H, W) map as a signed (dy, dx) offset, and its value.

    Starts at the grid maximum and takes Newton steps on the map's trigonometric (Fourier)
    interpolant, as STRCF/SRDCF do, which avoids the bias of per-axis parabolas towards whole
    cells. A step that leaves the cell around the grid maximum or lowers the value is dropped.
    """
    h, w = r.shape
    i, j = np.unravel_index(int(np.argmax(r)), r.shape)
    y0, x0, best = float(wrap(i, h)), float(wrap(j, w)), float(r[i, j])
    if iterations <= 0 or h < 3 or w < 3:
        return y0, x0, best
    spectrum = np.fft.fft2(r.astype(np.float64)) / (h * w)
    ky = 2j * np.pi * np.fft.fftfreq(h)  # d/dy of exp(2πi ky y / H), per unit of y
    kx = 2j * np.pi * np.fft.fftfreq(w)
    y, x = y0, x0
    for _ in range(iterations):
        ey, ex = np.exp(ky * y), np.exp(kx * x)
        gy = ((ky * ey) @ spectrum @ ex).real
        gx = (ey @ spectrum @ (kx * ex)).real
        hyy = ((ky * ky * ey) @ spectrum @ ex).real
        hxx = (ey @ spectrum @ (kx * kx * ex)).real
        hxy = ((ky * ey) @ spectrum @ (kx * ex)).real
        det = hyy * hxx - hxy * hxy
        if not (det > 0 and hyy < 0):  # not a local maximum of the interpolant: stop
            break
        y -= (hxx * gy - hxy * gx) / det
        x -= (hyy * gx - hxy * gy) / det
    if abs(y - y0) > 1 or abs(x - x0) > 1:
        return y0, x0, best
    value = float((np.exp(ky * y) @ spectrum @ np.exp(kx * x)).real)
    return (y, x, value) if value >= best else (y0, x0, best)


def local_maxima(r: np.ndarray, size: int = 3) -> tuple[np.ndarray, np.ndarray]:
    """Local maxima of a circular (H, W) map: rows, cols of pixels equal to the max of their
    ``size`` x ``size`` (odd; wrapped) neighbourhood and strictly above its minimum (no plateaus
    of a flat map). Sorted by value, highest first."""
    if size < 1 or size % 2 == 0:
        raise ValueError(f"local_maxima: size must be odd and positive, got {size}")
    # cv2's morphology on a wrap-padded copy (scipy.ndimage would cost 0.3 s of import)
    half = size // 2
    padded = np.pad(r, half, mode="wrap")
    kernel = np.ones((size, size), np.uint8)
    inner = (slice(half, half + r.shape[0]), slice(half, half + r.shape[1]))
    filtered = cv2.dilate(padded, kernel)[inner]
    lowest = cv2.erode(padded, kernel)[inner]
    rows, cols = np.nonzero((r == filtered) & (r > lowest))
    order = np.argsort(-r[rows, cols], kind="stable")
    return rows[order], cols[order]


def shift_spectrum(xf: np.ndarray, dy: float, dx: float, shape: tuple[int, int]) -> np.ndarray:
    """Half spectra (..., H, W//2+1) of maps translated so that x'(p) = x(p + (dy, dx)), circularly
    (sub-cell shifts interpolate in the Fourier domain)."""
    ky = np.fft.fftfreq(shape[0])[:, None]
    kx = np.fft.rfftfreq(shape[1])[None, :]
    phase = np.exp(2j * np.pi * (ky * dy + kx * dx)).astype(np.complex64)
    return xf * phase
