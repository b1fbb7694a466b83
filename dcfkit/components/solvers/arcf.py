"""ARCF's solver (Huang et al., ICCV 2019): BACF's ADMM plus the aberrance repression term.

ARCF adds γ/2 ‖M^{t-1}[ψ] - Σ_c x_c ⋆ h_c‖² to BACF's objective: the response on the
training sample is pulled towards the last frame's response map M^{t-1}, shifted ([ψ]) so
its peak moves as the target's did between the two frames. The authors' code
(tracker_HOGCN.m, as ARCF-HC) adds the term in the Fourier domain as ``γ M_prev .* model_xf``
with ``M_prev`` the *spatial* map (fftshift-ed, shifted by the change of its peak's index)
standing for the spectrum, and the term's data weight (1 + γ) on ``S_xx``. Per frequency the
g-step they solve is

    ((1 + γ) a aᴴ / K + μ I) g = a (ŷ + γ K M) / K + μ ĥ - l̂,

which is BACF's with the sample √(1 + γ) a and the label (ŷ + γ K M) / √(1 + γ). The map is
real but not point-symmetric, so their filter is not conjugate-symmetric (a complex spatial
filter); only its conjugate-symmetric part reaches a response computed as the real part of
the inverse transform, and that part is what this solver learns, exactly, from the
point-symmetric part (M(k) + M(-k)) / 2 of the map (the ADMM is real-linear and commutes with
conjugate reflection). It is therefore the authors' code as GNU Octave runs it, whose
``ifft2(.., 'symmetric')`` is the real part; MATLAB's 'symmetric' reads half the spectrum
instead, so the published MATLAB boxes may differ slightly (docs/results.md measures it).
"""
from __future__ import annotations

import dataclasses

import numpy as np

from dcfkit.components.base import running_average
from dcfkit.components.solvers.strcf_bacf import ADMMBacf, BACFParams, admm
from dcfkit.numerics.response import response as linear_response
from dcfkit.params import param

MAX_ABERRANCE = 1e4  # γ: the sample is scaled by √(1 + γ), kept well inside float32


@dataclasses.dataclass(frozen=True)
class ARCFParams(BACFParams):
    iterations: int = param(5, "E: ADMM iterations per frame (admm_iterations)", ge=1, le=10000)
    learning_rate: float = param(0.0192, "η: weight of the new sample in the running sample model", gt=0, le=1)
    aberrance: float = param(0.71, "γ of the aberrance term (admm_gamma); 0 is BACF", ge=0, le=MAX_ABERRANCE)


def point_symmetric(m: np.ndarray) -> np.ndarray:
    """(M(k) + M(-k)) / 2 over circular indices of an (H, W) map."""
    return 0.5 * (m + np.roll(m[::-1, ::-1], (1, 1), axis=(0, 1)))


class ADMMArcf(ADMMBacf):
    """ARCF-HC: :class:`ADMMBacf` whose label is pulled towards the last response.

    State between frames: the running sample model and last filter (BACF's), the last
    response map ``previous`` (H, W) float32 fftshift-ed, and its peak's index ``peak``."""

    name = "admm_arcf"
    Params = ARCFParams

    def reset(self):
        super().reset()
        self.previous: np.ndarray | None = None
        self.peak = np.zeros(2, int)
        self.current: tuple[np.ndarray, np.ndarray] | None = None

    def observe(self, detection):
        """The frame's response: the last map is shifted by its peak's move (``circshift`` in
        tracker_HOGCN.m), and this one replaces it once the frame is trained."""
        if self.current is not None:  # the last frame was not trained (a temporal θ = inf): its map is the last
            (self.previous, self.peak), self.current = self.current, None
        current = np.fft.fftshift(np.asarray(detection.response, np.float32))
        peak = np.array(np.unravel_index(int(np.argmax(current)), current.shape))
        if self.previous is not None:
            self.previous = np.roll(self.previous, tuple(peak - self.peak), axis=(0, 1))
        self.current = (current, peak)

    def train(self, xf, yf, w2, theta, fft):
        p = self.params
        self.model = running_average(self.model, xf, p.learning_rate)
        label = yf  # frame 1: M = 0, but the data term weighs 1 + γ all the same
        if self.previous is not None:
            shape, half = w2.shape, yf.shape[-1]
            label = yf + p.aberrance * shape[0] * shape[1] * point_symmetric(self.previous)[:, :half]
        scale = np.sqrt(1 + p.aberrance)
        vf, _ = admm((self.model * scale).astype(np.complex64), (label / scale).astype(np.complex64), w2, theta,
                     self.v_prev, p, fft)
        self.v_prev = vf
        if self.current is None:  # frame 1: the map is the new filter's response on the training sample
            first = np.fft.fftshift(linear_response(vf, xf, w2.shape, fft))
            self.previous, self.peak = first, np.array(np.unravel_index(int(np.argmax(first)), first.shape))
        else:
            (self.previous, self.peak), self.current = self.current, None
        return vf
