"""Moved to :mod:`dcfkit.running.tracking`."""
from dcfkit._moved import alias
from dcfkit.running import tracking as moved

alias(__name__, moved)
