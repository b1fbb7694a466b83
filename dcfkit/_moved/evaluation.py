"""Moved to :mod:`dcfkit.running.evaluation`."""
from dcfkit._moved import alias
from dcfkit.running import evaluation as moved

alias(__name__, moved)
