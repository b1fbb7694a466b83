"""Moved to :mod:`dcfkit.components.solvers`."""
from dcfkit._moved import alias
from dcfkit.components import solvers as moved

alias(__name__, moved)
