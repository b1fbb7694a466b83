"""Score tables as LaTeX for papers (booktabs): in each score column the best value is bold and
the second underlined; the caption names the protocol and, where intervals are shown, how they
were computed (:mod:`dcfkit.analysis.statistics`)."""
from __future__ import annotations

import math
from typing import Mapping
from typing import Sequence as Seq

from dcfkit.protocols import Protocol, get_protocol

_ESCAPES = {"\\": r"\textbackslash{}", "&": r"\&", "%": r"\%", "$": r"\$", "#": r"\#", "_": r"\_", "{": r"\{",
            "}": r"\}", "~": r"\textasciitilde{}", "^": r"\textasciicircum{}"}
_HEADERS = {"ao": "AO", "sr50": "SR$_{0.5}$", "sr75": "SR$_{0.75}$", "auc": "AUC", "precision": "Precision",
            "norm_precision": "Norm. prec.", "fps": "FPS", "tracker": "Tracker", "sequence": "Sequence",
            "attribute": "Attribute", "name": "Attribute name", "sequences": "Seq.", "missing": "Missing",
            "frames": "Frames", "variant": "Variant"}


def escape(text) -> str:
    """``text`` with LaTeX's special characters escaped."""
    return "".join(_ESCAPES.get(c, c) for c in str(text))


def latex_table(rows: Seq[Mapping], columns: Seq[str], protocol: str | Protocol,
                statistics: Mapping | None = None, name_key: str = "tracker") -> str:
    """``rows`` in ``columns`` as a booktabs ``table``. The protocol's score columns mark their
    best and second values; with ``statistics`` (:func:`~dcfkit.analysis.statistics.versus_baseline`)
    a row's mean scores carry their confidence intervals."""
    proto = get_protocol(protocol)
    places = {c: _places([r.get(c) for r in rows]) for c in columns if c in proto.score_keys}
    means = (statistics or {}).get("means", {})
    body = []
    for row in rows:
        cells = []
        for c in columns:
            text = _number(c, row.get(c))
            interval = means.get(row.get(name_key), {}).get(c)
            if c in places and row.get(c) is not None:
                mark = {1: r"\textbf{%s}", 2: r"\underline{%s}"}.get(places[c].get(row[c]))
                text = mark % text if mark else text
            if interval and math.isfinite(interval["ci_low"]):
                text += rf" {{\scriptsize [{interval['ci_low']:.3f}, {interval['ci_high']:.3f}]}}"
            cells.append(text)
        body.append(" & ".join(cells) + r" \\")
    caption = f"{escape(proto.describe())}. Best in bold, second underlined."
    if means:
        caption += f" In brackets: {escape(statistics['method'])}."
    align = "".join("l" if any(isinstance(r.get(c), str) for r in rows) else "r" for c in columns)
    head = " & ".join(escape(_HEADERS.get(c, c)) for c in columns) + r" \\"
    return "\n".join([r"\begin{table}", r"\centering", rf"\caption{{{caption}}}", rf"\begin{{tabular}}{{{align}}}",
                      r"\toprule", head, r"\midrule", *body, r"\bottomrule", r"\end{tabular}", r"\end{table}"]) + "\n"


def _places(values: Seq) -> dict:
    """value -> 1 for the highest finite value, 2 for the next distinct one."""
    distinct = sorted({v for v in values if isinstance(v, (int, float)) and math.isfinite(v)}, reverse=True)
    return {v: place for place, v in enumerate(distinct[:2], start=1)}


def _number(key: str, value) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "--"
    if isinstance(value, float):
        return f"{value:.1f}" if key == "fps" else f"{value:.3f}"
    return escape(value)
