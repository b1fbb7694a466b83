"""CSR-DCF's constrained filter (Lukežič et al., CVPR 2017, Sec. 3.2): each channel's filter
learnt by the augmented Lagrangian of the authors' ``create_csr_filter.m``, with the spatial
reliability map m as the constraint h = m ⊙ h_c, then averaged over frames.

Per channel, on unnormalised spectra (ĝ the unconstrained filter, l̂ the multiplier):

* start: ĥ = F(m ⊙ F⁻¹(ŝ_xy / (ŝ_xx + λ))), l̂ = 0, with ŝ_xy = x̂ ⊙ conj(ŷ), ŝ_xx = |x̂|²;
* ĝ = (ŝ_xy + μ ĥ - l̂) / (ŝ_xx + μ);
* ĥ = F(m ⊙ F⁻¹(μ ĝ + l̂) / (λ + μ));
* l̂ ← l̂ + μ (ĝ - ĥ), μ ← min(μ_max, β μ), for ``iterations`` rounds (the last stops after ĥ).

The mask comes as w² (``inf`` where m = 0, from the ``mask`` slot; a spatial regularizer's
finite w² adds to λ in the ĥ-step, and the start's m is (λ + μ)/(λ + μ + w²)). Spectra are half
spectra: every step keeps them conjugate-symmetric, so the authors' ``real()`` changes nothing.
The filter returned is (1 - η) h + η h_t (``learning_rate``); ``frame_filter`` holds h_t.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from dcfkit.components.base import running_average
from dcfkit.components.solvers.base import Solver
from dcfkit.params import param


@dataclasses.dataclass(frozen=True)
class CSRParams:
    iterations: int = param(4, "augmented Lagrangian iterations per frame (max_iters)", ge=1, le=1000)
    mu0: float = param(5.0, "μ: initial penalty", ge=1e-6, le=1e6)
    beta: float = param(3.0, "β: penalty growth per iteration", ge=1, le=100)
    mu_max: float = param(20.0, "μ_max: largest penalty", ge=1e-6, le=1e6)
    lam: float = param(0.05, "λ: ridge regularization (the authors' mu / 100 with mu = 5)", ge=0, le=1e6)
    learning_rate: float = param(0.02, "η: weight of each frame's filter in the running average", gt=0, le=1)


def csr_filter(xf: np.ndarray, yf: np.ndarray, w2: np.ndarray, p: CSRParams, fft) -> np.ndarray:
    """One frame's filter: (C, H, Wr) sample spectrum, (H, Wr) label spectrum, (H, W) w² (inf
    outside the mask) -> (C, H, Wr) complex64, each channel solved on its own."""
    shape = w2.shape
    w2 = np.asarray(w2, np.float32)
    sxy = (xf * yf.conj()).astype(np.complex64)
    sxx = (xf.real**2 + xf.imag**2).astype(np.float32)
    mu = p.mu0
    with np.errstate(divide="ignore"):  # w² = inf: the constraint's zero
        start = np.float32(p.lam + mu) / (np.float32(p.lam + mu) + w2)
    rows = constrained_rows(w2)  # h is zero outside them: their transforms are spared
    h = fft.irfft2_rows(sxy / (sxx + np.float32(p.lam)), shape, rows) * start
    hf = np.asarray(fft.rfft2_rows(h.astype(np.float32), rows), np.complex64)
    lf = np.zeros_like(hf)
    for e in range(p.iterations):
        m = np.float32(mu)
        gf = (sxy + m * hf - lf) / (sxx + m)
        with np.errstate(divide="ignore"):
            shrink = np.float32(1.0) / (np.float32(p.lam + mu) + w2)
        h = fft.irfft2_rows(m * gf + lf, shape, rows) * shrink
        hf = np.asarray(fft.rfft2_rows(h.astype(np.float32), rows), np.complex64)
        if e == p.iterations - 1:
            break
        lf = lf + m * (gf - hf)
        mu = min(p.mu_max, p.beta * mu)
    return hf


def constrained_rows(w2: np.ndarray) -> slice:
    """The band of rows of w² (H, W) from the first to the last holding a value below +inf:
    the constraint h = m ⊙ h_c keeps h zero in every other row (a NaN, which the regularizer's
    contract refuses, is inside, so that it reaches the filter as before)."""
    inside = np.flatnonzero((~np.isposinf(w2)).any(axis=1))
    return slice(int(inside[0]), int(inside[-1]) + 1) if inside.size else slice(0, 0)


class ADMMCsr(Solver):
    """CSR-DCF: each channel's filter constrained to the mask by an augmented Lagrangian
    (create_csr_filter.m), averaged over frames with η."""

    name = "admm_csr"
    Params = CSRParams
    terms = ("spatial",)

    def reset(self):
        self.model = None
        self.frame_filter = None

    def train(self, xf, yf, w2, theta, fft):
        self.frame_filter = csr_filter(xf, yf, w2, self.params, fft)
        self.model = running_average(self.model, self.frame_filter, self.params.learning_rate, np.complex64)
        return self.model
