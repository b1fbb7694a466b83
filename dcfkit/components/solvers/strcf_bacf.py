"""Filter solvers: ADMM for the spatially and temporally regularized objective (Eqs. 4–11).

Objective solved each frame (Eq. 2, with λ = 1 on the spatial term as in Eq. 10):

    E(h) = ½‖y - Σ_c m_c ⋆ h_c‖² + θ/2 Σ_c‖ĥ_c - v̂ˡ_c‖² + ½ Σ_c‖w ⊙ h_c‖²,

the data and spatial terms at their spatial value, the temporal term (and the ADMM penalty)
on unnormalised spectra, i.e. θK in spatial terms. This is the scaling of the authors' code,
for which the published θ, w and γ were chosen (STRCF's, BACF's and DR²Track's MATLAB
solve the v-step with B = S_xx + T(γ + μ) and the data terms over T); read with every term
on the spectra, Eqs. (7)–(9) would weigh the data K times more (K ≈ 2500: the temporal term
all but vanishes). ADMM splits h = v and alternates (per frame, from h = u = 0, Remark 1):

* v-step (Eqs. 6–9): per frequency, (a aᴴ/K + (θ+γ) I) v = a conj(ŷ)/K + θ v̂ˡ + γ ĥ - û,
  with a = m̂ at that frequency, solved by Sherman–Morrison;
* h-step (Eq. 10): h = γK (v + u/γ) / (w² + γK) in the spatial domain;
* multiplier (Eq. 11): û ← û + γ (v̂ - ĥ), then γ ← min(γ_max, β γ).

The multiplier is kept unscaled (u = γ z of the paper), the standard form when γ changes
between iterations; the paper's update z ← z + γ(v − h) agrees with it while γ = 1
(docs/reference.md). Spectra are half spectra (rfft2) of real maps, shape (C, H, W//2+1)
complex64; every equation above is per frequency, so solving on the half spectrum is exact.
ADMMStrcf also takes whole complex spectra (``tracker.spectra: full``, DR²Track's code).
"""
from __future__ import annotations

import dataclasses
import math
from typing import Callable

import numpy as np

from dcfkit.components.base import running_average
from dcfkit.components.solvers.base import Solver
from dcfkit.params import param


def _floats(z: np.ndarray) -> np.ndarray:
    """(..., W) complex64 as the (..., 2 W) float32 view the compiled kernels take (re, im interleaved)."""
    return z.view(np.float32)


def sherman_morrison_solve(a: np.ndarray, b: np.ndarray, c: float) -> np.ndarray:
    """Solve (a aᴴ + c I) x = b independently per pixel (Eq. 9): x = (b - a (aᴴb) / (c + aᴴa)) / c.

    a, b: (C, ...) complex, solved in complex64 by the ADMM's compiled v-step; c > 0.
    Returns (C, ...) complex64.
    """
    from dcfkit.components.solvers import kernels  # lazy: numba, compiled on first use

    shape = np.shape(b)
    a = np.ascontiguousarray(a, np.complex64).reshape(shape[0], 1, -1)
    b = np.ascontiguousarray(b, np.complex64).reshape(a.shape)
    aa = np.einsum("cij,cij->ij", a.conj(), a).real.astype(np.float32)
    t, x = np.empty(a.shape[1:], np.complex64), np.empty_like(a)
    kernels.v_step(_floats(a), _floats(b), _floats(b), _floats(b), 1.0, c, aa, True, _floats(t), _floats(x))
    return x.reshape(shape)


# Every penalty γ the ADMM uses: it divides by γ and by θ + γ, and multiplies by γK, in float32
PENALTY_RANGE = (1e-10, 1e10)


@dataclasses.dataclass(frozen=True)
class ADMMParams:
    iterations: int = param(4, "E: ADMM iterations per frame", ge=1, le=10000)
    gamma0: float = param(1.0, "γ⁰: initial penalty", ge=PENALTY_RANGE[0], le=PENALTY_RANGE[1])
    beta: float = param(10.0, "β: penalty growth per iteration", gt=0)
    gamma_max: float = param(10000.0, "γ_max: largest penalty", ge=PENALTY_RANGE[0], le=PENALTY_RANGE[1])
    h_step: str = param("standard", "'standard' h from v + u/γ (Eq. 10 with the unscaled multiplier), or 'authors' "
                        "from γ(v + u) as DR²Track's run_training.m (the same on the first iteration)",
                        choices=("standard", "authors"))

    def validate(self):
        """every penalty γ of the schedule (γ⁰, then γ ← min(gamma_max, beta·γ)) in [1e-10, 1e10];
        with h_step 'authors', the growth of the multiplier's error at most 1e10."""
        return schedule_problem(self)


# h_step 'authors' adds the unscaled multiplier u = γz to v (Eq. 10 reads z): inside the target
# box each iteration multiplies the multiplier's error by |1 - γ|; beyond this the filter is noise
AUTHORS_GROWTH_MAX = 1e10


def penalties(p: ADMMParams) -> list[float]:
    """γ of each of the E iterations: γ⁰, then γ ← min(γ_max, βγ) (Eq. 11)."""
    gammas = [p.gamma0]
    for _ in range(p.iterations - 1):
        gammas.append(min(p.gamma_max, p.beta * gammas[-1]))
    return gammas


def schedule_problem(p: ADMMParams) -> str | None:
    """Why the penalties of ``p`` cannot work in float32 (:data:`PENALTY_RANGE`,
    :data:`AUTHORS_GROWTH_MAX`), or None."""
    low = PENALTY_RANGE[0]  # gamma0 and gamma_max are within the range (their bounds): β is not
    schedule = penalties(p)
    worst = min(range(len(schedule)), key=schedule.__getitem__)
    if schedule[worst] < low:
        return (f"beta={p.beta:g} takes γ from gamma0={p.gamma0:g} down to {schedule[worst]:g} in iteration "
                f"{worst + 1} of {p.iterations} (γ ← min(gamma_max, beta·γ)); it must stay >= {low:g}")
    growth = math.prod(max(1.0, g - 1) for g in schedule[1:-1])  # the h-steps whose multiplier is used
    if p.h_step == "authors" and growth > AUTHORS_GROWTH_MAX:
        return (f"h_step 'authors' with iterations={p.iterations} and γ up to {max(schedule):g}: its multiplier's "
                f"error grows by |1 - γ| per iteration, {growth:.3g}-fold here, over {AUTHORS_GROWTH_MAX:g} "
                f"(fewer iterations, a smaller gamma_max, or h_step 'standard')")
    return None


def admm(xf: np.ndarray, yf: np.ndarray, w2: np.ndarray, theta: float, v_prev: np.ndarray | None,
         p: ADMMParams, fft, need_h: bool = False,
         theta_step: Callable[[np.ndarray], float] | None = None) -> tuple[np.ndarray, np.ndarray | None]:
    """Run E iterations of Eqs. (9)-(11).

    xf: (C, H, Wr) complex64 training sample; yf: (H, Wr) label spectrum; w2: (H, W) float32 w²
    in the patch layout, target centred like h itself (may hold inf); theta: temporal weight
    (ignored when v_prev is None); v_prev: (C, H, Wr) last frame's filter.
    Returns (v̂, ĥ), each (C, H, Wr) complex64. The trackers use v̂ only, so the last h-step
    and multiplier update, which cannot change it, run only when ``need_h``. ``theta_step``
    (AutoTrack's θ-subproblem) gives θ for the next iteration from this one's v̂, after every
    iteration but the last.
    """
    from dcfkit.components.solvers import kernels  # numba: compiled, or loaded from disk, on first use

    shape = w2.shape
    K = float(shape[0] * shape[1])
    # the data term at its spatial value (Parseval: 1/K of its unnormalised-spectrum value),
    # the temporal and penalty terms on the spectra: (a aᴴ/K + (θ+γ) I) v = a conj(ŷ)/K + ...
    s = np.float32(1.0 / np.sqrt(K))
    xf = np.ascontiguousarray(np.multiply(xf, s, dtype=np.complex64))
    yf = np.ascontiguousarray(np.multiply(yf, s, dtype=np.complex64))
    if v_prev is None:  # no previous filter, no temporal term (v_prev only fills the argument)
        theta, v_prev = 0.0, xf
    v_prev = np.ascontiguousarray(v_prev, np.complex64)
    aa = np.empty(xf.shape[1:], np.float32)
    rhs0 = np.empty_like(xf)
    kernels.prepare(_floats(xf), _floats(yf), _floats(v_prev), theta, aa, _floats(rhs0))
    t = np.empty(xf.shape[1:], np.complex64)
    vf, uf, g = (np.empty_like(xf) for _ in range(3))
    hf = uf  # h = u = 0 at first (Remark 1): the first v-step reads neither
    for e, gamma in enumerate(penalties(p)):
        first = e == 0
        # v-step (Eq. 9): Sherman-Morrison per frequency, b = a conj(ŷ) + θ v̂ˡ + γ ĥ - û
        kernels.v_step(_floats(xf), _floats(rhs0), _floats(hf), _floats(uf), gamma, theta + gamma, aa, first,
                       _floats(t), _floats(vf))
        if e == p.iterations - 1 and not need_h:
            return vf, None
        if theta_step is not None and e < p.iterations - 1:
            theta = theta_step(vf)
            kernels.prepare(_floats(xf), _floats(yf), _floats(v_prev), theta, aa, _floats(rhs0))
        # h-step (Eq. 10) in the spatial domain
        if not first:
            kernels.h_input(_floats(vf), _floats(uf), 1.0 if p.h_step == "authors" else gamma, _floats(g))
        h = fft.irfft2(vf if first else g, shape)
        h *= (gamma * K) / (w2 + gamma * K)
        h = h.astype(np.complex64 if np.iscomplexobj(h) else np.float32, copy=False)  # FullSpectra: complex
        hf = np.ascontiguousarray(fft.rfft2(h), np.complex64)
        # multiplier (Eq. 11) and penalty schedule
        kernels.multiplier(_floats(vf), _floats(hf), gamma, first, _floats(uf))
    return vf, hf


class ADMMStrcf(Solver):
    """STRCF/DR²Track: current sample, temporal term towards the previous filter (Eqs. 4–11)."""

    name = "admm_strcf"
    Params = ADMMParams
    full_spectra = True  # its h-step keeps a complex h whole (DR²Track's run_training.m)

    def reset(self):
        self.v_prev = None

    def train(self, xf, yf, w2, theta, fft):
        vf, _ = admm(xf, yf, w2, theta, self.v_prev, self.params, fft)
        self.v_prev = vf
        return vf


@dataclasses.dataclass(frozen=True)
class BACFParams(ADMMParams):
    iterations: int = param(2, "E: ADMM iterations per frame", ge=1, le=10000)
    learning_rate: float = param(0.013, "η: weight of the new sample in the running sample model", gt=0, le=1)


class ADMMBacf(Solver):
    """BACF: ADMM on a running average of the samples, x̂ ← (1-η) x̂ + η m̂; with the
    ``crop`` regularizer the h-step is BACF's h = P^T P ifft(...) with λ (Kiani Galoogahi 2017)."""

    name = "admm_bacf"
    Params = BACFParams

    def reset(self):
        self.model = None
        self.v_prev = None

    def train(self, xf, yf, w2, theta, fft):
        self.model = running_average(self.model, xf, self.params.learning_rate)
        vf, _ = admm(self.model, yf, w2, theta, self.v_prev, self.params, fft)
        self.v_prev = vf
        return vf

