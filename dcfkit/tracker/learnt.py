"""The tracker's hooks for a learnt mask and channel weights (CSR-DCF's spatial and channel
reliability): each does nothing unless its slot holds a component."""
from __future__ import annotations

import numpy as np

from dcfkit.numerics.response import channel_responses
from dcfkit.tracker.checks import read_only


def channel_maps(tracker, samples: np.ndarray, hf: np.ndarray | None = None) -> np.ndarray:
    """(S, C, H, W) per-channel responses of (S, C, H, Wr) samples to ``hf`` (the tracker's filter)."""
    return channel_responses(tracker.hf if hf is None else hf, samples, tracker.geometry.filter_size, tracker.fft)


def masked_w2(tracker, image: np.ndarray) -> np.ndarray:
    """The w² this frame's filter is trained with: the spatial regularizer's, ``inf`` outside the
    mask the mask component makes from the frame at the tracker's position and scale."""
    g = tracker.geometry
    mask = tracker.mask.make(image, tracker.position.copy(), g.base_target * tracker.scale, g.region(tracker.scale),
                             g.filter_size)
    return read_only(np.where(mask, tracker.w2, np.float32(np.inf)).astype(np.float32, copy=False))


def learn_channels(tracker, xf: np.ndarray) -> None:
    """Give the channel weights the per-channel responses of the training sample ``xf`` to the
    filter learnt from it alone (the solver's ``frame_filter``, else the filter it returned)."""
    frame = getattr(tracker.solver, "frame_filter", None)
    tracker.channel_weights.learn(channel_maps(tracker, xf[None], tracker.hf if frame is None else frame)[0])
