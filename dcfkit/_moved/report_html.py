"""Moved to :mod:`dcfkit.analysis.report_html`."""
from dcfkit._moved import alias
from dcfkit.analysis import report_html as moved

alias(__name__, moved)
