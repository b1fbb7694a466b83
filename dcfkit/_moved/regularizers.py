"""Moved to :mod:`dcfkit.components.regularizers`."""
from dcfkit._moved import alias
from dcfkit.components import regularizers as moved

alias(__name__, moved)
