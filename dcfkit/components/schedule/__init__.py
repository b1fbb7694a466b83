"""Schedules (``schedule:`` in a config): on which frames the filter is trained.

* :mod:`.sparse` -- ``every_frame``, and ECO's ``sparse`` updates;
* :mod:`.gated` -- ``reliable``: gated learning, only on frames the reliability component trusts.

Where to add one: subclass :class:`~dcfkit.components.schedule.base.Schedule`."""
from __future__ import annotations

from dcfkit.components.schedule.base import Schedule
from dcfkit.components.schedule.gated import Reliable
from dcfkit.components.schedule.sparse import EveryFrame, Sparse

BUILTIN = (EveryFrame, Sparse, Reliable)

__all__ = ["BUILTIN", "EveryFrame", "Reliable", "Schedule", "Sparse"]
