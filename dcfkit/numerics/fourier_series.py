"""Fourier series of feature maps on the continuous domain (C-COT / ECO, Danelljan et al.).

A map of N samples is read as the coefficients of a periodic function on [0, T): its
interpolation with a kernel b (Eq. 3 of C-COT) has the Fourier coefficients X[k] b̂(k/N) / N
(Eq. 4), k = -(N-1)/2 .. (N-1)/2 for odd N. Every spectrum here is *centred*: index i of an
axis of odd length K is frequency i - (K-1)/2. A *half* spectrum keeps the columns of
frequency <= 0 (the last column is frequency 0): the others follow by conjugate symmetry.
Arrays are (..., K, L) complex; the block axes in front are channels or samples.
"""
from __future__ import annotations

import numpy as np


def cubic_spline_fourier(f: np.ndarray, a: float) -> np.ndarray:
    """The continuous Fourier transform B(f) = ∫ b(x) e^{-i2πfx} dx of Keys' cubic kernel
    b(x) = (a+2)|x|³ - (a+3)|x|² + 1 on |x| ≤ 1, a|x|³ - 5a|x|² + 8a|x| - 4a on 1 < |x| < 2,
    0 beyond (real and even); B(0) = 1. Closed form from integrating by parts."""
    f = np.asarray(f, dtype=float)
    out = np.ones_like(f)
    nz = f != 0
    w = 2 * np.pi * f[nz]
    # ∫ b(x) cos(wx) dx over [-2, 2], by parts four times (b is piecewise cubic, C¹ at 0, 1, 2)
    num = (6 * (4 + 2 * a) - 24 * np.cos(w) - 12 * a * np.cos(2 * w)
           - (12 + 16 * a) * w * np.sin(w) - 4 * a * w * np.sin(2 * w))
    out[nz] = num / w**4
    return out


def interp_fourier(n: int, a: float, centering: bool = True) -> np.ndarray:
    """(n,) complex128: the kernel's Fourier coefficients B(k/n)/n for the n centred
    frequencies k of an n-sample axis (n odd), times e^{-iπk/n} with ``centering`` (the
    kernel centred on each sample, not at its left edge: ECO's interpolation_centering)."""
    k = np.arange(n) - (n - 1) / 2
    out = cubic_spline_fourier(k / n, a) / n
    return out * np.exp(-1j * np.pi * k / n) if centering else out.astype(complex)


def odd(size) -> np.ndarray:
    """Each size made odd (even + 1): the number of Fourier coefficients kept per axis."""
    size = np.asarray(size, dtype=int)
    return size + (size + 1) % 2


def centred_dft(x: np.ndarray) -> np.ndarray:
    """(..., H, W) real -> (..., H', W') complex centred DFT, H', W' odd (``odd``): an even
    axis gains the frequency +N/2 as the conjugate mirror of -N/2 (ECO's cfft2)."""
    h, w = x.shape[-2:]
    xf = np.fft.fftshift(np.fft.fft2(x, axes=(-2, -1)), axes=(-2, -1))
    if h % 2 and w % 2:
        return xf
    out = np.zeros(x.shape[:-2] + tuple(odd((h, w))), dtype=xf.dtype)
    out[..., :h, :w] = xf
    if h % 2 == 0:
        out[..., -1, :] = np.conj(out[..., 0, ::-1])
    if w % 2 == 0:
        out[..., :, -1] = np.conj(out[..., ::-1, 0])
    return out


def half(xf: np.ndarray) -> np.ndarray:
    """The columns of frequency <= 0 of a centred spectrum."""
    return xf[..., : (xf.shape[-1] + 1) // 2]


def full(hf: np.ndarray) -> np.ndarray:
    """A half spectrum completed by conjugate symmetry: X[-k] = conj(X[k])."""
    return np.concatenate([hf, np.conj(hf[..., ::-1, -2::-1])], axis=-1)


def frequencies(size) -> tuple[np.ndarray, np.ndarray]:
    """(ky (H, 1), kx (1, Wh)): the frequencies of a half spectrum of odd ``size`` (H, W)."""
    h, w = int(size[0]), int(size[1])
    ky = np.arange(h) - (h - 1) // 2
    kx = np.arange((w + 1) // 2) - (w - 1) // 2
    return ky[:, None].astype(float), kx[None, :].astype(float)


def shift(hf: np.ndarray, dy: float, dx: float) -> np.ndarray:
    """A half spectrum translated by (dy, dx) radians of its period (ECO's shift_sample)."""
    ky, kx = frequencies((hf.shape[-2], 2 * hf.shape[-1] - 1))
    return (hf * (np.exp(1j * dy * ky) * np.exp(1j * dx * kx))).astype(hf.dtype)


def sample(xf: np.ndarray) -> np.ndarray:
    """A full centred spectrum (..., H, W) sampled on its own grid: x[n] = Σ_k X[k] e^{i2πkn/N},
    real part (sample n is at 2πn/N, n = 0 at the origin)."""
    h, w = xf.shape[-2:]
    return (h * w) * np.fft.ifft2(np.fft.ifftshift(xf, axes=(-2, -1)), axes=(-2, -1)).real


def symmetrize(hf: np.ndarray) -> np.ndarray:
    """Make the frequency-0 column of a half spectrum conjugate symmetric in ky (in place;
    ECO's symmetrize_filter: the lower half mirrored from the upper)."""
    dc = (hf.shape[-2] - 1) // 2
    hf[..., dc + 1:, -1] = np.conj(hf[..., :dc, -1][..., ::-1])
    return hf


def window_of(target_shape, block_shape) -> tuple[slice, slice]:
    """The slices of a larger half spectrum that hold a block's frequencies."""
    py = (target_shape[-2] - block_shape[-2]) // 2
    px = target_shape[-1] - block_shape[-1]
    return slice(py, target_shape[-2] - py), slice(px, None)


def newton_maximum(scores_f: np.ndarray, iterations: int) -> tuple[float, float, int]:
    """The maximum of the real Fourier series with full centred coefficients ``scores_f``
    (S, H, W), over S scales: the best grid sample of each, refined by ``iterations`` Newton
    steps on the series (gradient and Hessian in closed form), kept only where the refined
    score is higher (ECO's optimize_scores). Returns (dy, dx) in grid cells, wrapped to
    [-H/2, H/2), and the scale index."""
    s, h, w = scores_f.shape
    grid = sample(scores_f).reshape(s, -1)
    best = np.argmax(grid, axis=1)
    start_score = grid[np.arange(s), best]
    row, col = np.unravel_index(best, (h, w))
    # the grid position as an angle in [-π, π)
    y0 = 2 * np.pi * ((row + (h - 1) // 2) % h - (h - 1) // 2) / h
    x0 = 2 * np.pi * ((col + (w - 1) // 2) % w - (w - 1) // 2) / w
    ky = np.arange(h) - (h - 1) // 2
    kx = np.arange(w) - (w - 1) // 2
    y, x = y0.copy(), x0.copy()
    for _ in range(iterations):
        ey, ex = np.exp(1j * ky[None] * y[:, None]), np.exp(1j * kx[None] * x[:, None])  # (S, H), (S, W)
        resp_x = np.einsum("shw,sw->sh", scores_f, ex)
        y_resp = np.einsum("sh,shw->sw", ey, scores_f)
        value = np.einsum("sh,sh->s", ey, resp_x)
        gy = -np.einsum("sh,sh->s", ky * ey, resp_x).imag
        gx = -np.einsum("sw,sw->s", y_resp, kx * ex).imag
        hyy = (-np.einsum("sh,sh->s", ky**2 * ey, resp_x) + 1j * value).real
        hxx = (-np.einsum("sw,sw->s", y_resp, kx**2 * ex) + 1j * value).real
        hxy = (-np.einsum("sh,shw,sw->s", ky * ey, scores_f, kx * ex)).real
        det = hyy * hxx - hxy * hxy
        y, x = y - (hxx * gy - hxy * gx) / det, x - (hyy * gx - hxy * gy) / det
    ey, ex = np.exp(1j * ky[None] * y[:, None]), np.exp(1j * kx[None] * x[:, None])
    score = np.einsum("sh,shw,sw->s", ey, scores_f, ex).real
    worse = ~(score >= start_score)  # a step that lost, or left the numbers: the grid sample
    score[worse], y[worse], x[worse] = start_score[worse], y0[worse], x0[worse]
    k = int(np.argmax(score))
    dy = (np.mod(y[k] + np.pi, 2 * np.pi) - np.pi) / (2 * np.pi) * h
    dx = (np.mod(x[k] + np.pi, 2 * np.pi) - np.pi) / (2 * np.pi) * w
    return float(dy), float(dx), k
