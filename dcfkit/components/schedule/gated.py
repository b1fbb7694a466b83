"""``reliable``: gated learning. The filter is trained only on frames whose detection the
reliability component judged reliable (score ≥ 1): LMCF's high-confidence update (Wang et al.,
CVPR 2017, Sec. 3.3) and MOSSE's stopped update under a low PSR (Bolme et al., CVPR 2010).
On the other frames the filter stays where it was, so a lost target's background is not
learnt."""
from __future__ import annotations

from dcfkit.components.reliability.base import unreliable
from dcfkit.components.schedule.base import Schedule


class Reliable(Schedule):
    """Train on frame 1 and on frames whose detection scored ≥ 1 (needs ``reliability:``)."""

    name = "reliable"
    needs_reliability = True  # the tracker refuses a config without a reliability component

    def __init__(self, params=None):
        super().__init__(params)
        self.reset()

    def reset(self) -> None:
        self.last_score = None  # the last detection's reliability score

    def observe(self, detection) -> None:
        self.last_score = getattr(detection, "score", None)

    def due(self, frame: int) -> bool:
        return frame == 1 or not unreliable(self.last_score)
