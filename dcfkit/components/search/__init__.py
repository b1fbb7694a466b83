"""Search strategies: where the next frame's search area is centred (Eq. 14).

Where to add one: subclass :class:`~dcfkit.components.search.base.Search`."""
from __future__ import annotations

from dcfkit.components.search.base import MAX_COORDINATE, Search
from dcfkit.components.search.strategies import MAX_GAIN, LastPosition, MotionAware

BUILTIN = (LastPosition, MotionAware)

__all__ = ["BUILTIN", "LastPosition", "MAX_COORDINATE", "MAX_GAIN", "MotionAware", "Search"]
