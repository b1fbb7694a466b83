"""CSR-DCF's channel reliability (Lukežič et al., CVPR 2017, Sec. 3.3), as the authors'
``create_csr_tracker.m`` and ``track_csr_tracker.m`` compute it."""
from __future__ import annotations

import dataclasses

import numpy as np

from dcfkit.components.base import running_average
from dcfkit.components.channel_weights.base import ChannelWeights
from dcfkit.numerics.maxima import maxima_components
from dcfkit.params import param


def maxima_values(maps: np.ndarray) -> list[np.ndarray]:
    """The values of the regional maxima of each (H, W) map of a (C, H, W) stack, highest first:
    one value per connected plateau of MATLAB's ``imregionalmax`` (``bwconncomp``)."""
    maps = np.asarray(maps, np.float32)
    labels, n = maxima_components(maps)
    value, channel = np.zeros(n + 1, np.float32), np.zeros(n + 1, np.int64)
    value[labels] = maps  # every pixel of a plateau has its value
    channel[labels] = np.arange(len(maps))[:, None, None]
    order = np.lexsort((-value[1:], channel[1:]))
    kept_channel, kept_value = channel[1:][order], value[1:][order]
    return np.split(kept_value, np.searchsorted(kept_channel, np.arange(1, len(maps))))


def detection_reliability(maps: np.ndarray, floor: float = 0.5) -> np.ndarray:
    """Per channel, 1 - (second highest / highest regional maximum) of its response
    normalised to [0, 1], at least ``floor``; 1 for a flat map or a single maximum
    (track_csr_tracker's channel_discr). (C, H, W) -> (C,) float64."""
    flat = maps.reshape(len(maps), -1)
    low, high = flat.min(axis=1), flat.max(axis=1)
    span = np.where(high > low, high - low, 1).astype(np.float32)
    normalised = (maps - low[:, None, None]) / span[:, None, None]
    out = np.ones(len(maps))
    for c, peaks in enumerate(maxima_values(normalised)):
        if high[c] > low[c] and len(peaks) > 1 and peaks[0] > 0:
            out[c] = max(1.0 - peaks[1] / peaks[0], floor)
    return out


class CSRReliability(ChannelWeights):
    """CSR-DCF's channel reliability: each channel's weight is its filter's highest response on
    its own training sample, times 1 - the ratio of its second to first response peak at the
    last detection, normalised and averaged over frames (Lukežič et al. 2017, Eqs. 12-13)."""

    name = "csr_reliability"

    @dataclasses.dataclass(frozen=True)
    class Params:
        learning_rate: float = param(0.02, "weight of each frame's reliabilities (channels_weight_lr)", gt=0, le=1)
        floor: float = param(0.5, "least detection reliability of a channel", ge=0, le=1)
        detection: bool = param(True, "multiply by the detection reliability (false: learning reliability only)")

    def reset(self) -> None:
        self.weights = None
        self.discrimination = None

    def learn(self, maps):
        fresh = maps.reshape(len(maps), -1).max(axis=1).astype(np.float64)
        if self.discrimination is not None and self.params.detection:
            fresh = fresh * self.discrimination
        total = fresh.sum()
        if not (np.isfinite(total) and total > 0):  # no channel responds: keep what was learnt
            self.weights = np.full(len(maps), 1 / len(maps)) if self.weights is None else self.weights
            return
        fresh /= total
        if self.weights is None:
            self.weights = fresh
        else:
            mixed = running_average(self.weights, fresh, self.params.learning_rate)
            self.weights = mixed / mixed.sum()

    def combine(self, maps):
        return np.einsum("c,schw->shw", self.weights.astype(np.float32), maps, optimize=False)

    def observe(self, maps):
        self.discrimination = detection_reliability(maps, self.params.floor)
