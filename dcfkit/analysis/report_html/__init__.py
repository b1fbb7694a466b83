"""Self-contained HTML report pages: ``dcfkit report --html`` and every ``dcfkit ablate`` run
write one ``report.html`` holding the tables, the plots, each sequence's frames with the
boxes, and the provenance of the results, with its data, script and styles inline.

Plots are SVG drawn in the page by ``report.js`` (a few kilobytes, no library) from the
data embedded once as JSON; ``document`` writes the file, ``sections`` and ``pages`` build
its data, ``thumbnails`` the frames and ``provenance`` reads the result sidecars.
"""
from dcfkit.analysis.report_html.document import render, write_page
from dcfkit.analysis.report_html.pages import PAGE, evaluation_sections, report_page, write_html_report

__all__ = ["PAGE", "evaluation_sections", "render", "report_page", "write_html_report", "write_page"]
