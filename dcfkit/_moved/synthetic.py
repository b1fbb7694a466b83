"""Moved to :mod:`dcfkit.datasets.synthetic`."""
from dcfkit._moved import alias
from dcfkit.datasets import synthetic as moved

alias(__name__, moved)
