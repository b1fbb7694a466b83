"""Moved to :mod:`dcfkit.tracker.confidence`."""
from dcfkit._moved import alias
from dcfkit.tracker import confidence as moved

alias(__name__, moved)
