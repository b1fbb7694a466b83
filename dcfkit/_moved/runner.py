"""Moved to :mod:`dcfkit.running.runner`."""
from dcfkit._moved import alias
from dcfkit.running import runner as moved

alias(__name__, moved)
