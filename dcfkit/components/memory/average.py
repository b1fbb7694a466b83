"""The running average: one sample, (1 - η) old + η new (BACF's and ARCF's sample model)."""
from __future__ import annotations

import dataclasses

import numpy as np

from dcfkit.components.base import running_average
from dcfkit.components.memory.base import Memory
from dcfkit.params import param


class RunningAverage(Memory):
    """One slot of weight 1 holding the running average of the samples (the first as it is)."""

    name = "running_average"

    @dataclasses.dataclass(frozen=True)
    class Params:
        learning_rate: float = param(0.013, "η: weight of the new sample", gt=0, le=1)

    def reset(self) -> None:
        self.samples, self.weights, self.count = [], np.zeros(1, np.float32), 0

    def insert(self, sample) -> None:
        if self.count == 0:
            self._allocate(sample, 1)
            for store, block in zip(self.samples, sample):
                store[0] = block
            self.count, self.weights[0] = 1, 1.0
            return
        rate = self.params.learning_rate
        for store, block in zip(self.samples, sample):
            store[0] = running_average(store[0], np.asarray(block), rate)
