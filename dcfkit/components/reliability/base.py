"""The reliability kind: a score of how sure a detection is, 1 at the component's threshold."""
from __future__ import annotations

from dcfkit.components.base import Component, Contract
from dcfkit.contracts import scalar


RELIABLE = 1.0  #: the score at and above which a frame is reliable, whatever the component


def unreliable(score: float | None) -> bool:
    """Whether a reliability ``score`` judges its frame unreliable (None: no component, no verdict)."""
    return score is not None and score < RELIABLE


class Reliability(Component, declares="reliability"):
    """Scores detections (``reliability:`` in a config; none by default). The tracker calls
    ``reset()`` at every ``init``; ``score(detection)`` on every detection, the search's and
    each re-detection candidate's, so it must not change the component; then, once the frame's
    detection is decided, ``observe(detection, score)`` with it (a component that keeps a
    history learns here). A score ≥ 1 is a reliable frame; it is also the presence score the
    tracker writes, so higher must mean surer."""

    contract = Contract(required={"score": ("detection",)}, optional={"observe": ("detection", "score"), "reset": ()},
                        returns={"score": scalar(0.0, float("inf"), inf=True)})

    def score(self, detection) -> float:
        """How reliable ``detection`` (:class:`~dcfkit.components.labels.base.Detection`) is: ≥ 1 reliable."""
        raise NotImplementedError

    def observe(self, detection, score: float) -> None:
        """The frame's detection as decided, with its score."""

    def reset(self) -> None:
        """Forget the frames of an earlier target."""
