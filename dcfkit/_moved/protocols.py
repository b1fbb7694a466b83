"""Moved to :mod:`dcfkit.analysis.protocols`."""
from dcfkit._moved import alias
from dcfkit.analysis import protocols as moved

alias(__name__, moved)
