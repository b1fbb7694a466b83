"""Built-in schedules: every frame, and ECO's sparse updates (Danelljan et al., CVPR 2017,
Sec. 3.3: the filter trained every N_s-th frame)."""
from __future__ import annotations

import dataclasses

from dcfkit.components.schedule.base import Schedule
from dcfkit.params import param


class EveryFrame(Schedule):
    """Train on every frame (what a tracker without a schedule does)."""

    name = "every_frame"

    def due(self, frame: int) -> bool:
        return True


class Sparse(Schedule):
    """Train on every frame before ``after_frame``, then only once ``gap`` frames have passed
    without training (N_s = gap + 1; ECO's train_gap and skip_after_frame)."""

    name = "sparse"

    @dataclasses.dataclass(frozen=True)
    class Params:
        gap: int = param(5, "frames left untrained between two trainings (N_s - 1)", ge=0, le=10000)
        after_frame: int = param(10, "the first frame from which the gap applies (frames before it all train)",
                                 ge=1, le=10**9)

    def reset(self) -> None:
        self.since = None  # frames since the last training; None: never trained

    def __init__(self, params=None):
        super().__init__(params)
        self.reset()

    def due(self, frame: int) -> bool:
        p = self.params
        train = frame < p.after_frame or self.since is None or self.since >= p.gap
        self.since = 0 if train else self.since + 1
        return train
