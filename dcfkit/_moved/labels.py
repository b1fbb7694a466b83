"""Moved to :mod:`dcfkit.components.labels`."""
from dcfkit._moved import alias
from dcfkit.components import labels as moved

alias(__name__, moved)
