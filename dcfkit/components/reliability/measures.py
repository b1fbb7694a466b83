"""Built-in reliability scores read from the response map of a detection.

``lmcf``: LMCF's high-confidence test (Wang et al., "Large Margin Object Tracking with
Circulant Feature Maps", CVPR 2017, Sec. 3.3): a frame is reliable when its peak F_max and its
APCE are at least β1 and β2 times their historical averages, over every earlier frame. The
score is the smaller of the two ratios ``value / (β · average)``, so 1 is the test's boundary.
Averaging the reliable frames alone would let a gate that holds the filter close for good: the
first frames' peaks, of a filter learnt from one or two samples, set a bar that a filter which
no longer learns never reaches again; over every frame, a lasting drop lowers the bar until the
gate opens.

``psr``: MOSSE's peak-to-sidelobe ratio (Bolme et al., CVPR 2010, Sec. 3.4), ``(peak - μ) /
σ`` of the map outside a window around the peak, divided by the threshold below which MOSSE
calls the target lost.
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np

from dcfkit.components.reliability.base import Reliability
from dcfkit.errors import ConfigError
from dcfkit.params import param
from dcfkit.numerics.response import apce


class LMCF(Reliability):
    """Peak and APCE against β1 and β2 times their averages over the frames so far."""

    name = "lmcf"

    @dataclasses.dataclass(frozen=True)
    class Params:
        peak_ratio: float = param(0.7, "β1: the peak must reach this fraction of its average over the earlier "
                                  "frames (0: not tested)", ge=0, le=100)
        apce_ratio: float = param(0.45, "β2: the APCE must reach this fraction of its average over the earlier "
                                  "frames (0: not tested)", ge=0, le=100)

    def __init__(self, params=None):
        super().__init__(params)
        if self.params.peak_ratio == 0 and self.params.apce_ratio == 0:
            raise ConfigError("lmcf: peak_ratio and apce_ratio are both 0: nothing is tested (set one above 0)")
        self.reset()

    def reset(self) -> None:
        self.sums, self.count = np.zeros(2), 0  # of (peak, APCE) over the frames observed

    @staticmethod
    def _measures(detection) -> np.ndarray:
        r = np.asarray(detection.response, dtype=np.float64)
        return np.array([r.max(), apce(r)])

    def score(self, detection) -> float:
        values = self._measures(detection)
        # no frame yet: the frame is its own average (its ratios are 1 / β)
        means = self.sums / self.count if self.count else values
        ratios = [_ratio(v, beta * m) for v, m, beta in zip(values, means, (self.params.peak_ratio,
                                                                             self.params.apce_ratio)) if beta > 0]
        return float(min(ratios))

    def observe(self, detection, score: float) -> None:
        self.sums += self._measures(detection)
        self.count += 1


def _ratio(value: float, bar: float) -> float:
    """``value / bar``, clipped at 0; ``inf`` for a bar at or below 0 (nothing to fall short of)."""
    if bar <= 0:
        return math.inf
    return max(value / bar, 0.0)


class PSR(Reliability):
    """MOSSE's peak-to-sidelobe ratio over ``threshold``."""

    name = "psr"

    @dataclasses.dataclass(frozen=True)
    class Params:
        threshold: float = param(7.0, "the PSR below which the target counts as lost (MOSSE: 7)", gt=0, le=1e6)
        exclude: int = param(5, "half-width in cells of the window around the peak left out of the sidelobe "
                             "(MOSSE: 11 x 11 pixels, 5)", ge=0, le=1000)

    def score(self, detection) -> float:
        psr = peak_to_sidelobe(detection.response, detection.peak, self.params.exclude)
        return max(psr / self.params.threshold, 0.0)


def peak_to_sidelobe(response: np.ndarray, peak: tuple[int, int], exclude: int) -> float:
    """``(R[peak] - μ) / σ`` over the cells of ``response`` outside the (2 exclude + 1)² window
    centred on ``peak``, taken circularly (the map's layout); 0 for a flat sidelobe or none."""
    r = np.asarray(response, dtype=np.float64)
    h, w = r.shape
    keep = np.ones((h, w), dtype=bool)
    rows = (peak[0] + np.arange(-exclude, exclude + 1)) % h
    cols = (peak[1] + np.arange(-exclude, exclude + 1)) % w
    keep[np.ix_(rows, cols)] = False
    side = r[keep]
    if side.size == 0:
        return 0.0
    sigma = float(side.std())
    return float((r[peak] - side.mean()) / sigma) if sigma > 0 else 0.0
