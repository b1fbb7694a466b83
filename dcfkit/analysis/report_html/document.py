"""One self-contained HTML file from a page's data: the styles, the script and the data inline.

The data travels as one JSON block that ``report.js`` reads and draws into the page with
text nodes only, so no user text (tracker, sequence, config value) is ever parsed as HTML.
In the JSON, ``<``, ``>``, ``&`` and ``/`` are escaped (and in the header's text, HTML's
characters and ``/``): user text cannot end the block or add markup, and the file holds no
URL at all. A Content-Security-Policy allows the page's own script (by its
hash), inline styles and ``data:`` images, and nothing from anywhere else.
"""
from __future__ import annotations

import base64
import hashlib
import html
import json
import math
from importlib import resources
from pathlib import Path
from typing import Mapping

import numpy as np

from dcfkit.store.files import atomic_write

DIGITS = 4  # decimals of the floats in the page's data: scores are shown with 3


def compact(obj):
    """``obj`` ready for JSON: arrays as lists, floats rounded to :data:`DIGITS` decimals,
    non-finite floats as None."""
    if isinstance(obj, Mapping):
        return {str(k): compact(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [compact(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return compact(obj.tolist())
    if isinstance(obj, np.generic):
        return compact(obj.item())
    if isinstance(obj, float):
        return round(obj, DIGITS) if math.isfinite(obj) else None
    if obj is None or isinstance(obj, (str, int)):
        return obj
    return str(obj)


def script_json(data) -> str:
    """``data`` as JSON that is safe inside ``<script type="application/json">``."""
    text = json.dumps(compact(data), ensure_ascii=False, separators=(",", ":"), allow_nan=False)
    for char, escaped in (("&", "\\u0026"), ("<", "\\u003c"), (">", "\\u003e"), ("/", "\\/")):
        text = text.replace(char, escaped)
    return text


def _asset(name: str) -> str:
    return resources.files(__package__).joinpath(name).read_text(encoding="utf-8")


def render(page: Mapping) -> str:
    """The HTML document of ``page``: ``title``, ``protocol`` (the line naming the scoring
    protocol), ``subtitle``, ``trackers`` and ``sections`` (:mod:`~dcfkit.analysis.report_html.sections`)."""
    script = _asset("report.js")
    digest = base64.b64encode(hashlib.sha256(script.encode("utf-8")).digest()).decode("ascii")
    policy = f"default-src 'none'; img-src data:; style-src 'unsafe-inline'; script-src 'sha256-{digest}'"

    def esc(text: str) -> str:  # "/" as a character reference too: no URL in the file, whatever the text
        return html.escape(text).replace("/", "&#47;")

    return (
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
        f"<meta http-equiv=\"Content-Security-Policy\" content=\"{policy}\">\n"
        "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
        f"<title>{esc(page['title'])}</title>\n<style>\n{_asset('report.css')}</style>\n</head>\n<body>\n"
        f"<header>\n<h1>{esc(page['title'])}</h1>\n<p class=\"protocol\">{esc(page['protocol'])}</p>\n"
        f"<p class=\"subtitle\">{esc(page.get('subtitle', ''))}</p>\n<nav id=\"nav\"></nav>\n</header>\n"
        "<main id=\"main\"><noscript>This report draws its tables and plots with JavaScript; the same numbers "
        "are in the .csv, .md and .json files beside it.</noscript></main>\n"
        f"<script type=\"application/json\" id=\"report-data\">{script_json(page)}</script>\n"
        f"<script>{script}</script>\n</body>\n</html>\n")


def write_page(page: Mapping, path: Path) -> Path:
    """Write :func:`render` of ``page`` to ``path`` atomically; returns ``path``."""
    atomic_write(Path(path), render(page))
    return Path(path)
