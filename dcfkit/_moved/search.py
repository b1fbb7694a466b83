"""Moved to :mod:`dcfkit.components.search`."""
from dcfkit._moved import alias
from dcfkit.components import search as moved

alias(__name__, moved)
