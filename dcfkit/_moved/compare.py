"""Moved to :mod:`dcfkit.analysis.compare`."""
from dcfkit._moved import alias
from dcfkit.analysis import compare as moved

alias(__name__, moved)
