"""Moved to :mod:`dcfkit.running.results`."""
from dcfkit._moved import alias
from dcfkit.running import results as moved

alias(__name__, moved)
