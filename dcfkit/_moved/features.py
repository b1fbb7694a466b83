"""Moved to :mod:`dcfkit.components.features`."""
from dcfkit._moved import alias
from dcfkit.components import features as moved

alias(__name__, moved)
