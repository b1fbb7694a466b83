"""Memories (``memory:`` in a config): the training samples a tracker keeps and their weights.

Where to add one: subclass :class:`~dcfkit.components.memory.base.Memory`."""
from __future__ import annotations

from dcfkit.components.memory.average import RunningAverage
from dcfkit.components.memory.base import Memory
from dcfkit.components.memory.gmm import GaussianMixture

BUILTIN = (RunningAverage, GaussianMixture)

__all__ = ["BUILTIN", "GaussianMixture", "Memory", "RunningAverage"]
