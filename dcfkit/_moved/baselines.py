"""Moved to :mod:`dcfkit.integrations.opencv`."""
from dcfkit._moved import alias
from dcfkit.integrations import opencv as moved

alias(__name__, moved)
