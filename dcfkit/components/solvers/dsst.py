"""DSST's translation filter: multichannel ridge regression over all cyclic shifts, in closed
form per frequency (Danelljan et al., "Accurate Scale Estimation for Robust Visual
Tracking", BMVC 2014, Eqs. 1–4; TPAMI 2017 as "Discriminative Scale Space Tracking").

Objective of one frame (DSST Eq. 1), with dcfkit's correlation R = F⁻¹(Σ_c conj(ĥ_c) ⊙ x̂_c)
(:mod:`dcfkit.numerics.response`):

    ε(h) = ‖R(h, x) - y‖² + λ Σ_c ‖h_c‖².

Per frequency it is min_g |aᵀ g - ŷ|² + λ |g|² with a = x̂, g = conj(ĥ) (the 1/K of Parseval on
both terms cancels), whose normal equations (conj(a) aᵀ + λ I) g = conj(a) ŷ have the rank-one
solution g = conj(a) ŷ / (|a|² + λ). So ĥ_c = A_c / (B + λ) with A_c = conj(ŷ) x̂_c and
B = Σ_c |x̂_c|² (DSST Eq. 2): exact for one frame. Over frames A and B are each averaged with
the learning rate η (DSST Eq. 3), the first frame taken whole, and the detection
F⁻¹(Σ_c conj(A_c) ⊙ ẑ_c / (B + λ)) (DSST Eq. 4) is the linear response of ĥ = A / (B + λ).

λ is DSST's, on unnormalised spectra as their code (the same value as a spatial-domain λ,
by the Parseval argument above). Half spectra (rfft2): every equation is per frequency.
There is no spatial or temporal term: the solver declares none (``terms``).
"""
from __future__ import annotations

import dataclasses

import numpy as np

from dcfkit.components.base import running_average
from dcfkit.components.solvers.base import Solver
from dcfkit.numerics.fft import multiply
from dcfkit.params import param


@dataclasses.dataclass(frozen=True)
class RidgeParams:
    # ĥ divides by B + λ, which is λ alone where the sample has no energy
    lam: float = param(0.01, "λ: ridge regularization, ĥ = A / (B + λ)", ge=1e-10, le=1e10)
    learning_rate: float = param(0.025, "η: weight of the new frame in the numerator A and denominator B",
                                 gt=0, le=1)


class Ridge(Solver):
    """DSST's translation filter: ĥ = A / (B + λ), A_c = conj(ŷ) x̂_c and B = Σ_c |x̂_c|², each
    averaged over frames with η (DSST Eqs. 2–3). Detection is the linear response (Eq. 4)."""

    name = "ridge"
    Params = RidgeParams
    terms = ()

    def reset(self):
        self.num = None  # A, (C, H, Wr) complex64
        self.den = None  # B, (H, Wr) float32

    def train(self, xf, yf, w2, theta, fft):
        num = multiply(np.conj(yf)[None], xf)
        den = np.einsum("chw,chw->hw", xf.real, xf.real) + np.einsum("chw,chw->hw", xf.imag, xf.imag)
        eta = self.params.learning_rate
        self.num = running_average(self.num, num, eta, np.complex64)
        self.den = running_average(self.den, den, eta, np.float32)
        return (self.num / (self.den + np.float32(self.params.lam))).astype(np.complex64, copy=False)
