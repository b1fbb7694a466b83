"""Moved to :mod:`dcfkit.running.platforms`."""
from dcfkit._moved import alias
from dcfkit.running import platforms as moved

alias(__name__, moved)
