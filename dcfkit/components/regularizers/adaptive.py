"""AutoTrack's regularizers (Li et al., CVPR 2020), set every frame from the response's variation.

The local response variation Π compares this frame's response R with the
last one's, each shifted so its peak sits at the origin:
Π = |(R[ψ] - R_prev[ψ_prev]) / R_prev[ψ_prev]| element-wise. From it:

* ``local_variation`` (spatial): inside the target box, w = δ log(Π + 1),
  where the response is reliable the filter is regularized less; outside it w stays large;
* ``global_variation`` (temporal): θ̃ = ζ / (1 + log(ν ‖Π‖₂ + 1)), the
  reference the ADMM's θ-step starts from (``admm_autotrack``); when ‖Π‖₂ crosses a
  threshold the frame is taken as an occlusion and the filter is kept (θ = ∞).

As in the authors' AutoTrack_optimized.m: the first detection only records the response;
the peak shift uses floor of the sub-cell peak; ‖Π‖₂ is the spectral norm (MATLAB's
``norm`` of a matrix) divided by 10⁴; w inside the box keeps its last value between frames.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from dcfkit.components.regularizers.base import MAX_THETA, MAX_WEIGHT, PLACEMENTS, TemporalRegularizer, target_mask
from dcfkit.components.regularizers.windows import BoxWindow
from dcfkit.params import param


def response_variation(previous: tuple[np.ndarray, tuple[float, float]], detection) -> np.ndarray:
    """Π: (H, W) float32, circular layout, of the last (response, (dy, dx)) and this detection.
    Where the last shifted response is 0, Π is inf (or NaN where both are)."""
    def centred(response, offset):
        return np.roll(response, (-int(np.floor(offset[0])), -int(np.floor(offset[1]))), axis=(0, 1))

    now = centred(detection.response, detection.offset or (0.0, 0.0))
    before = centred(*previous)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.abs(np.abs(now - before) / before).astype(np.float32)


def _record(detection) -> tuple[np.ndarray, tuple[float, float]]:
    return np.array(detection.response, np.float32), tuple(detection.offset or (0.0, 0.0))


class LocalVariation(BoxWindow):
    """AutoTrack's spatial window: STRCF's box window (``outside`` beyond the target box,
    ``inside`` on it) whose inside becomes δ log(Π + 1) of the latest detections from the
    second on. State: the last response and its peak."""

    name = "local_variation"

    @dataclasses.dataclass(frozen=True)
    class Params(BoxWindow.Params):
        inside: float = param(1e-3, "w inside the target box before the response varies (reg_window_min)",
                              ge=0, le=MAX_WEIGHT)
        placement: str = param("authors", "where an odd box sits in an even patch: 'centred' or 'authors' "
                               "(init_regwindow's, a cell lower and to the right)", choices=PLACEMENTS)
        delta: float = param(0.2, "δ: w inside the box is δ log(Π + 1)", ge=0, le=MAX_WEIGHT)

    def reset(self):
        self.previous = None
        self.mask = None

    def weights_squared(self, shape, target_cells):
        self.mask = target_mask(shape, target_cells, self.params.placement)
        return super().weights_squared(shape, target_cells)

    def adapt(self, w2, detection):
        previous, self.previous = self.previous, _record(detection)
        if previous is None:
            return w2
        variation = np.fft.fftshift(response_variation(previous, detection))  # circshift(floor(size / 2))
        w2 = w2.copy()
        with np.errstate(over="ignore"):  # Π = inf (a zero in the last response): w = inf, h = 0 there
            # log in float64: numpy's float32 log is the processor's (SIMD) estimate
            w2[self.mask] = (self.params.delta * np.log(variation[self.mask].astype(np.float64) + 1)) ** 2
        return w2


class GlobalVariation(TemporalRegularizer):
    """AutoTrack's temporal weight: the reference θ̃ = ζ / (1 + log(ν η + 1)), η = ‖Π‖₂ / 10⁴,
    or ∞ (keep the filter) when η ≥ φ. ``theta`` is ζ, used until the second
    detection. State: the last response and its peak."""

    name = "global_variation"

    @dataclasses.dataclass(frozen=True)
    class Params:
        theta: float = param(13.0, "ζ: the reference θ before any variation, and its scale (zeta)",
                             ge=0, le=MAX_THETA)
        nu: float = param(0.2, "ν: how fast θ̃ falls as the response varies", ge=0, le=1e6)
        occlusion: float = param(0.3, "φ: from this η on the frame is an occlusion and the filter is kept "
                                 "(inf: never)", gt=0)
        norm_scale: float = param(1e4, "η = ‖Π‖₂ / norm_scale (the authors' 1e4)", ge=1e-6, le=1e12)

    def reset(self):
        self.previous = None

    def weight(self, detection):
        if detection is None:
            return self.params.theta
        previous, self.previous = self.previous, _record(detection)
        if previous is None:
            return self.params.theta
        variation = response_variation(previous, detection)
        if not np.all(np.isfinite(variation)):  # a zero in the last response: no sensible η
            return np.inf
        eta = float(np.linalg.norm(variation.astype(np.float64), 2)) / self.params.norm_scale
        if eta >= self.params.occlusion:
            return np.inf
        return self.params.theta / (1 + np.log(self.params.nu * eta + 1))
