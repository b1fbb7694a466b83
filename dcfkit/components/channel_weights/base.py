"""The channel_weights kind: how much each feature channel's response counts at detection."""
from __future__ import annotations

import numpy as np

from dcfkit.components.base import Component, Contract
from dcfkit.contracts import array


class ChannelWeights(Component, declares="channel_weights"):
    """Weights the per-channel responses of a linear filter (``channel_weights:`` in a config;
    none by default: the channels' responses are summed, Eq. 12). The tracker calls
    ``reset()`` at every ``init``; ``learn`` after every training with the per-channel
    responses of the training sample to the filter learnt from it alone (the solver's
    ``frame_filter``); on every later frame ``combine`` with the per-channel responses of the
    search samples, whose result the target is located on, then ``observe`` with those of the
    chosen scale. Maps are circular (the target at cell (0, 0)), float32."""

    contract = Contract(required={"learn": ("maps",), "combine": ("maps",)},
                        optional={"observe": ("maps",), "reset": ()},
                        returns={"combine": array(lambda args, c: (args[0].shape[0], *args[0].shape[2:]),
                                                  finite=False)})

    def learn(self, maps: np.ndarray) -> None:
        """(C, H, W) responses of the training sample's channels to this frame's filter."""
        raise NotImplementedError

    def combine(self, maps: np.ndarray) -> np.ndarray:
        """(S, C, H, W) per-channel responses of the S search samples -> (S, H, W) response."""
        raise NotImplementedError

    def observe(self, maps: np.ndarray) -> None:
        """(C, H, W) per-channel responses at the scale the target was found at."""

    def reset(self) -> None:
        """Forget what earlier targets left."""
