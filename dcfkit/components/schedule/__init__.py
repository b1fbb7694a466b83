"""Schedules (``schedule:`` in a config): on which frames the filter is trained.

Where to add one: subclass :class:`~dcfkit.components.schedule.base.Schedule`."""
from __future__ import annotations

from dcfkit.components.schedule.base import Schedule
from dcfkit.components.schedule.sparse import EveryFrame, Sparse

BUILTIN = (EveryFrame, Sparse)

__all__ = ["BUILTIN", "EveryFrame", "Schedule", "Sparse"]
