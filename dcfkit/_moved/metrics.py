"""Moved to :mod:`dcfkit.analysis.metrics`."""
from dcfkit._moved import alias
from dcfkit.analysis import metrics as moved

alias(__name__, moved)
