"""The memory kind: the training samples a tracker keeps, and the weight of each.

A sample is a list of arrays (one per feature block, any shapes, complex or real), the same
shapes every time. ``insert`` adds one, after which ``samples`` holds per block an array
(N, ...) of the N slots (unused ones zero), ``weights`` (N,) float32 the slots' weights
(zero for unused; the used ones sum to 1) and ``count`` the slots in use. A running average
(BACF's sample model: one slot, weight 1) is the simplest member; ECO's Gaussian mixture
(``gmm``) the richest.
"""
from __future__ import annotations

from typing import Sequence

import numpy as np

from dcfkit.components.base import Component, Contract


class Memory(Component, declares="memory"):
    """Keeps weighted training samples. The tracker calls ``reset()`` at every ``init`` (a new
    target), ``insert(sample)`` once per frame it learns from, then reads ``samples``,
    ``weights`` and ``count``; ``replace(index, sample)`` puts a changed version of a kept
    sample in its slot (ECO re-projects the first frame's sample after learning its
    projection)."""

    contract = Contract(required={"reset": (), "insert": ("sample",)}, optional={"replace": ("index", "sample")})

    samples: list[np.ndarray]
    weights: np.ndarray
    count: int

    def reset(self) -> None:
        """Forget every sample."""
        raise NotImplementedError

    def insert(self, sample: Sequence[np.ndarray]) -> None:
        """Add this frame's sample (per block an array)."""
        raise NotImplementedError

    def replace(self, index: int, sample: Sequence[np.ndarray]) -> None:
        """Put ``sample`` in slot ``index`` in place of what is there, its weight kept."""
        for store, block in zip(self.samples, sample):
            store[index] = block

    def _allocate(self, sample: Sequence[np.ndarray], capacity: int) -> None:
        """Zeroed slots shaped like ``sample``."""
        self.samples = [np.zeros((capacity,) + np.shape(b), dtype=np.asarray(b).dtype) for b in sample]
