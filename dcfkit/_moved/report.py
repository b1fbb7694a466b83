"""Moved to :mod:`dcfkit.analysis.report`."""
from dcfkit._moved import alias
from dcfkit.analysis import report as moved

alias(__name__, moved)
