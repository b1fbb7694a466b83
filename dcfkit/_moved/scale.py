"""Moved to :mod:`dcfkit.components.scale`."""
from dcfkit._moved import alias
from dcfkit.components import scale as moved

alias(__name__, moved)
