"""The tracker: Algorithm 1 of the DR²Track paper over registered components."""
from __future__ import annotations

from dcfkit.tracker.checks import MAX_BOX_TO_IMAGE, MAX_CHANNELS
from dcfkit.tracker.tracker import Tracker, load_tracker

__all__ = ["MAX_BOX_TO_IMAGE", "MAX_CHANNELS", "Tracker", "load_tracker"]
