"""Moved to :mod:`dcfkit.datasets.video`."""
from dcfkit._moved import alias
from dcfkit.datasets import video as moved

alias(__name__, moved)
