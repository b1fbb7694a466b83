"""The schedule kind: on which frames the filter is trained (an update gate).

``due(frame)`` is asked once per frame the tracker could learn from (1-based frame
numbers, frame 1 included) and says whether it trains the filter on that frame; a frame
not due still keeps its sample where the tracker has a memory. The component counts for
itself: the answer may depend on the frames before (ECO's sparse updates), and later gates
may depend on what the detection saw (``observe``)."""
from __future__ import annotations

from dcfkit.components.base import Component, Contract


def _is_bool(value, args, component) -> str | None:
    return None if isinstance(value, bool) else f"{value!r}, expected True or False"


class Schedule(Component, declares="schedule"):
    """Decides whether a frame trains the filter. The tracker calls ``reset()`` at every
    ``init``, ``observe(detection)`` after each detection (optional) and ``due(frame)`` once
    per frame it could train on; frame 1 must be due (there is no filter before it)."""

    contract = Contract(required={"due": ("frame",)}, optional={"reset": (), "observe": ("detection",)},
                        returns={"due": _is_bool})

    def reset(self) -> None:
        """Forget the frames of an earlier target."""

    def observe(self, detection) -> None:
        """What this frame's detection saw (the built-ins decide by frame numbers alone)."""

    def due(self, frame: int) -> bool:
        raise NotImplementedError


