"""ECO's filter training (Danelljan et al., CVPR 2017): the normal equations of Eq. (5) on
half spectra, their preconditioned conjugate gradient, and the spatial regularization as a
convolution in the Fourier domain (SRDCF's w, C-COT Eq. 9).

A filter is a list of blocks, each (D, H, Wh) complex64: the half spectrum (frequencies
kx <= 0, the last column kx = 0; :mod:`dcfkit.numerics.fourier_series`) of D channels on the
block's odd (H, W) grid. The largest block's grid is the output grid; the others sit in its
middle (:func:`~dcfkit.numerics.fourier_series.window_of`). Vectors of the solver are lists
of arrays; their inner product counts every column twice but kx = 0 once (the half spectrum
stands for the whole, whose kx > 0 half mirrors it).
"""
from __future__ import annotations

from typing import Callable, Sequence

import numpy as np

from dcfkit.numerics.fourier_series import window_of


def regularization_filter(support, target, minimum: float, edge: float, power: float,
                          threshold: float) -> np.ndarray:
    """(rh, rw) float32: the non-zero middle of the DFT of SRDCF's window
    w = (edge - min) (|y / (target_h/2)|^p + |x / (target_w/2)|^p) + min on the ``support``
    grid (pixels), its coefficients under ``threshold`` x the largest set to zero and the
    constant raised so that the sparse window's minimum is ``minimum`` (ECO's get_reg_filter)."""
    h, w = int(support[0]), int(support[1])
    ry, rx = 0.5 * np.asarray(target, dtype=float)
    y = (np.arange(h) - (h - 1) / 2)[:, None]
    x = (np.arange(w) - (w - 1) / 2)[None, :]
    window = (edge - minimum) * (np.abs(y / ry) ** power + np.abs(x / rx) ** power) + minimum
    dft = np.fft.fft2(window) / (h * w)
    dft[np.abs(dft) < threshold * np.abs(dft).max()] = 0
    sparse = np.fft.ifft2(dft).real
    dft[0, 0] = dft[0, 0] - h * w * sparse.min() + minimum
    dft = np.fft.fftshift(dft)
    rows, cols = np.any(dft != 0, axis=1), np.any(dft != 0, axis=0)
    return dft[rows][:, cols].real.astype(np.float32)


def apply_regularization(hf: np.ndarray, reg: np.ndarray) -> np.ndarray:
    """W^H W f for the half spectrum ``hf`` (D, H, Wh): the full spectrum (the mirrored
    columns it needs appended) convolved twice with the symmetric ``reg`` (rh, rw), cut back
    to the half spectrum (ECO's lhs_operation, its last loop)."""
    rh, rw = reg.shape
    pad = min(rw - 1, hf.shape[-1] - 1)
    if pad > 0:
        ext = np.concatenate([hf, np.conj(hf[..., ::-1, -2:-2 - pad:-1])], axis=-1)
    else:
        ext = hf
    conv = _convolve_full(ext, reg)
    conv = conv[..., : conv.shape[-1] - pad]
    return _convolve_valid(conv, reg)


def _convolve_full(x: np.ndarray, k: np.ndarray) -> np.ndarray:
    """2-D full convolution over the last two axes, one shifted add per tap of the small ``k``."""
    kh, kw = k.shape
    h, w = x.shape[-2:]
    out = np.zeros(x.shape[:-2] + (h + kh - 1, w + kw - 1), dtype=x.dtype)
    for i, j in zip(*np.nonzero(k)):
        out[..., i:i + h, j:j + w] += k[i, j] * x
    return out


def _convolve_valid(x: np.ndarray, k: np.ndarray) -> np.ndarray:
    """2-D 'valid' convolution over the last two axes (the kernel flipped, as convn)."""
    kh, kw = k.shape
    h, w = x.shape[-2] - kh + 1, x.shape[-1] - kw + 1
    out = np.zeros(x.shape[:-2] + (h, w), dtype=x.dtype)
    for i, j in zip(*np.nonzero(k)):
        out += k[i, j] * x[..., kh - 1 - i:kh - 1 - i + h, kw - 1 - j:kw - 1 - j + w]
    return out


def inner(a: Sequence[np.ndarray], b: Sequence[np.ndarray]) -> float:
    """Re <a, b> over half spectra: every column twice, the kx = 0 column once."""
    total = 0.0
    for x, y in zip(a, b):
        total += 2 * np.vdot(x, y).real - np.vdot(x[..., -1], y[..., -1]).real
    return float(total)


def output_shape(blocks: Sequence[np.ndarray]) -> tuple[int, int]:
    """(H, Wh) of the output grid: the tallest block's (ECO's k1, the first of the tallest)."""
    k1 = int(np.argmax([b.shape[-2] for b in blocks]))
    return blocks[k1].shape[-2], blocks[k1].shape[-1]


def correlate_samples(samples: Sequence[np.ndarray], hf: Sequence[np.ndarray]) -> np.ndarray:
    """(N, H, Wh): Σ over blocks and channels of sample x filter, each block added at its
    frequencies of the output grid (the responses' spectra of the N samples)."""
    shape = output_shape(hf)
    out = np.zeros((samples[0].shape[0],) + shape, dtype=np.complex64)
    for x, f in zip(samples, hf):
        win = window_of(shape, f.shape)
        out[:, win[0], win[1]] += (x * f).sum(axis=1)  # broadcast and sum: 4x numpy's complex einsum
    return out


def lhs_filter(hf: list[np.ndarray], samples: Sequence[np.ndarray], weights: np.ndarray,
               reg: Sequence[np.ndarray]) -> list[np.ndarray]:
    """A f of the normal equations: Σ_n w_n X_n^H X_n f + W^H W f (ECO's lhs_operation).
    ``samples``: per block (N, D, H, Wh); ``weights`` (N,)."""
    sh = correlate_samples(samples, hf) * weights[:, None, None].astype(np.float32)
    out = []
    for x, f, r in zip(samples, hf, reg):
        win = window_of(sh.shape[1:], f.shape)
        data = (sh[:, None, win[0], win[1]] * np.conj(x)).sum(axis=0)
        out.append((data + apply_regularization(f, r)).astype(np.complex64))
    return out


def preconditioner(energy: np.ndarray, reg: np.ndarray, data_param: float, reg_param: float) -> np.ndarray:
    """ECO's diagonal preconditioner of one block from its sample energy |x|² (D, H, Wh):
    (1 - r)(d e + (1 - d) mean_D e) + r Σ reg²."""
    reg_energy = float(np.sum(reg.astype(np.float64) ** 2))
    diag = ((1 - reg_param) * (data_param * energy + (1 - data_param) * energy.mean(axis=0))
            + reg_param * reg_energy).astype(np.float32)
    return np.maximum(diag, np.float32(1e-30))  # a frequency without energy: no division by 0


def pcg(apply_a: Callable, b: list, precondition: Callable, dot: Callable, x0: list, iterations: int,
        fletcher_reeves: bool, forget: float = 0.0, state: dict | None = None) -> tuple[list, dict]:
    """Preconditioned conjugate gradient (ECO's pcg_ccot): Fletcher-Reeves or Polak-Ribière β
    (clipped at 0), warm-started from ``x0`` and, with a ``state`` and ``forget`` > 0, from
    the last search direction, its ρ divided by ``forget`` (the direction's weight decays).
    Returns x and the state to pass next time. Not split: the method's one loop."""
    x = [np.array(v, copy=True) for v in x0]
    p, rho, r_prev = None, 1.0, None
    if state and forget > 0:
        p = state.get("p")
        rho = state["rho"] / forget if state.get("rho") is not None else rho
        r_prev = None if fletcher_reeves else state.get("r_prev")
    r = [bi - ai for bi, ai in zip(b, apply_a(x))]
    for it in range(iterations):
        z = precondition(r)
        rho1, rho = rho, dot(r, z)
        if rho == 0 or not np.isfinite(rho):
            break
        if it == 0 and p is None:
            p = z
        else:
            beta = rho / rho1 if fletcher_reeves or r_prev is None else (rho - dot(r_prev, z)) / rho1
            if beta == 0 or not np.isfinite(beta):
                break
            p = [zi + max(beta, 0.0) * pi for zi, pi in zip(z, p)]
        q = apply_a(p)
        pq = dot(p, q)
        if pq <= 0 or not np.isfinite(pq):
            break
        alpha = rho / pq
        if not np.isfinite(alpha):
            break
        r_prev = None if fletcher_reeves else r
        x = [xi + alpha * pi for xi, pi in zip(x, p)]
        if it < iterations - 1:
            r = [ri - alpha * qi for ri, qi in zip(r, q)]
    return x, {"p": p, "rho": rho, "r_prev": r_prev}
