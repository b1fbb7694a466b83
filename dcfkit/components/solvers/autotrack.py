"""AutoTrack's solver (Li et al., CVPR 2020): STRCF's ADMM with θ one of the unknowns.

AutoTrack adds (θ - θ̃)²/2 to STRCF's objective, θ̃ the reference that the temporal
regularizer ``global_variation`` sets each frame; the ADMM gains a θ-step,
θ = θ̃ - ‖ĝ - ĝ_prev‖² / (2ε), between its iterations. As the authors' AutoTrack_optimized.m
runs it: from the third frame on (before, θ is the one the tracker passes throughout), the
first iteration with θ = ``theta_first`` (their ``mu = zeta``), then a θ-step after every
iteration but the last, with ‖·‖ the spectral norm (MATLAB's ``norm`` of a matrix) of the
last feature channel's full unnormalised spectrum (their loop over channels keeps only the
last one's).
"""
from __future__ import annotations

import dataclasses

import numpy as np

from dcfkit.components.regularizers.base import MAX_THETA
from dcfkit.components.solvers.strcf_bacf import ADMMParams, ADMMStrcf, admm
from dcfkit.params import param


@dataclasses.dataclass(frozen=True)
class AutoTrackParams(ADMMParams):
    epsilon: float = param(1.0, "ε of the θ-step θ = θ̃ - ‖ĝ - ĝ_prev‖² / (2ε)", ge=1e-10, le=1e10)
    theta_first: float = param(13.0, "θ of the first iteration on frames with the θ-step (the authors' "
                               "mu = zeta, the global_variation regularizer's theta)", ge=0, le=MAX_THETA)


def full_spectrum(half: np.ndarray, width: int) -> np.ndarray:
    """The (H, W) spectrum of a real map from its (H, W//2+1) half: F(k, l) = conj(F(-k, -l))."""
    rows = -np.arange(half.shape[0]) % half.shape[0]
    cols = width - np.arange(half.shape[1], width)
    return np.concatenate([half, np.conj(half[rows][:, cols])], axis=1)


class ADMMAutoTrack(ADMMStrcf):
    """AutoTrack: :class:`ADMMStrcf` with the θ-step. The tracker's θ is the reference θ̃ on
    frames with the θ-step, and the θ of every iteration before them. State between frames:
    the last filter and how many frames were trained."""

    name = "admm_autotrack"
    full_spectra = False  # its θ-step mirrors half spectra
    Params = AutoTrackParams

    def reset(self):
        super().reset()
        self.trained = 0

    def train(self, xf, yf, w2, theta, fft):
        step = None
        if self.trained >= 2:  # the authors' ``frame > 2``: frames 1 and 2 are trained with θ fixed
            last = full_spectrum(self.v_prev[-1].astype(np.complex128), w2.shape[1])
            scale = 2 * self.params.epsilon

            def step(vf):
                change = full_spectrum(vf[-1].astype(np.complex128), w2.shape[1]) - last
                return reference - float(np.linalg.norm(change, 2)) ** 2 / scale

            theta, reference = self.params.theta_first, theta  # θ̃ enters through the θ-step only
        vf, _ = admm(xf, yf, w2, theta, self.v_prev, self.params, fft, theta_step=step)
        self.v_prev = vf
        self.trained += 1
        return vf
