"""Score tables as LaTeX for papers (booktabs): :func:`latex_table` marks in each score column
the best value bold and the second underlined; :func:`comparison_table` gives each tracker's
scores with their confidence intervals and its paired difference from a baseline with its
interval, Wilcoxon p and the sequences won, tied and lost (:mod:`dcfkit.analysis.statistics`).
Each caption names the experiment, the protocol and the sequences; the tables need
``\\usepackage{booktabs}``, and for the comparison tables ``\\usepackage{graphicx}``."""
from __future__ import annotations

import math
from typing import Mapping
from typing import Sequence as Seq

from dcfkit.analysis.stats import columns
from dcfkit.analysis.stats.columns import DIFFERENCE, LOWER_IS_BETTER, MEAN, headers, interval_cell
from dcfkit.analysis.stats.results import Comparison
from dcfkit.protocols import Protocol, get_protocol

__all__ = ["LOWER_IS_BETTER", "comparison_table", "escape", "interval_cell", "latex_table", "long_term_table"]

_ESCAPES = {"\\": r"\textbackslash{}", "&": r"\&", "%": r"\%", "$": r"\$", "#": r"\#", "_": r"\_", "{": r"\{",
            "}": r"\}", "~": r"\textasciitilde{}", "^": r"\textasciicircum{}",
            "<": r"\textless{}", ">": r"\textgreater{}", "\u2212": "-"}
_HEADERS = {"ao": "AO", "sr50": "SR$_{0.5}$", "sr75": "SR$_{0.75}$", "auc": "AUC", "precision": "Precision",
            "norm_precision": "Norm. prec.", "fps": "FPS", "tracker": "Tracker", "sequence": "Sequence",
            "attribute": "Attribute", "name": "Attribute name", "sequences": "Seq.", "missing": "Missing",
            "frames": "Frames", "variant": "Variant", "accuracy": "Accuracy", "failures": "Failures",
            "eao": "EAO"}


def escape(text) -> str:
    """``text`` with LaTeX's special characters escaped (``--`` stays two hyphens: ``--max-frames``)."""
    return "".join(_ESCAPES.get(c, c) for c in str(text)).replace("--", "-{}-")


def latex_table(rows: Seq[Mapping], columns: Seq[str], protocol: str | Protocol, setting: Seq[str] = ()) -> str:
    """``rows`` in ``columns`` as a booktabs ``table``, its caption ``setting`` (sentences naming
    the experiment and the sequences) and the protocol; the protocol's score columns mark their
    best and second values."""
    proto = get_protocol(protocol)
    places = {c: _places([r.get(c) for r in rows]) for c in columns if c in proto.score_keys}
    body = []
    for row in rows:
        cells = []
        for c in columns:
            text = _number(c, row.get(c))
            if c in places and row.get(c) is not None:
                mark = {1: r"\textbf{%s}", 2: r"\underline{%s}"}.get(places[c].get(row[c]))
                text = mark % text if mark else text
            cells.append(text)
        body.append(" & ".join(cells) + r" \\")
    caption = _sentences([*setting, proto.describe()]) + " Best in bold, second underlined."
    align = "".join("l" if any(isinstance(r.get(c), str) for r in rows) else "r" for c in columns)
    head = " & ".join(escape(_HEADERS.get(c, c)) for c in columns) + r" \\"
    return _table(caption, align, [head], body)


def comparison_table(statistics: Comparison, setting: Seq[str], name: str = "Tracker",
                     lead: Seq[tuple[str, Mapping[str, str]]] = (), datasets: Mapping[str, int] | None = None) -> str:
    """A :class:`~dcfkit.analysis.stats.results.Comparison` as a booktabs ``table`` a paper can
    take: per tracker and score the columns declared for ``latex``
    (:mod:`dcfkit.analysis.stats.columns`: its mean with the confidence interval, its paired
    difference from the baseline (Delta) with the interval, the Wilcoxon p (``*``: significant
    after Holm's correction) and the sequences won/tied/lost (fewer failures win); ``--`` for
    the baseline's). ``setting``: the caption's first sentences (experiment, protocol); ``lead``:
    columns before the scores, (header, tracker -> LaTeX cell); ``datasets``: the sequences
    scored per dataset, named in the caption."""
    keys, baseline, skip = statistics.scores, statistics.baseline, 1 + len(lead)
    per = len(headers(MEAN, "latex")) + len(headers(DIFFERENCE, "latex"))  # columns per score
    head = [" & " * skip + " & ".join(rf"\multicolumn{{{per}}}{{c}}{{{escape(_HEADERS.get(k, k))}}}"
                                      for k in keys) + r" \\",
            "".join(rf"\cmidrule(lr){{{1 + skip + per * i}-{skip + per * (i + 1)}}}" for i in range(len(keys))),
            " & ".join([escape(name), *(escape(h) for h, _ in lead)]
                       + [" & ".join(headers(MEAN, "latex") + headers(DIFFERENCE, "latex"))] * len(keys)) + r" \\"]
    body = []
    for tracker, found in statistics.means.items():
        row = [escape(tracker), *(cells.get(tracker, "--") for _, cells in lead)]
        for key in keys:
            difference = statistics.differences.get(tracker, {}).get(key)
            row += columns.cells(MEAN, "latex", found[key], key)
            row += (columns.cells(DIFFERENCE, "latex", difference, key) if difference is not None
                    else ["--"] * len(headers(DIFFERENCE, "latex")))
        body.append(" & ".join(row) + r" \\")
    over = f" ({', '.join(f'{d} {n}' for d, n in datasets.items())})" if datasets else ""  # escaped with the sentence
    caption = _sentences([*setting, f"Means over the {statistics.sequences} sequences every {name.lower()} ran{over}",
                          statistics.method])
    caption += (rf" $\Delta$: the paired difference from {escape(baseline)} (--: {escape(baseline)} itself); "
                rf"$p$: its Wilcoxon p, $^{{*}}$ where significant after Holm's correction across the "
                rf"comparisons of a score (corrected $p < 0.05$); W/T/L: the sequences it scored better, "
                rf"the same, worse on.")
    return _table(caption, "l" * skip + "r" * per * len(keys), head, body, wide=True)


#: the headers of the long-term table (:mod:`dcfkit.analysis.longterm_report`), LaTeX already
LONG_TERM_HEADERS = {"tracker": "Tracker", "f": "F", "precision": "Pr", "recall": "Re", "threshold": r"$\tau$",
                     "sequences": "Seq.", "absent": "Absent"}


def long_term_table(rows: Seq[Mapping], columns: Seq[str], setting: Seq[str], left_out: Seq[str] = ()) -> str:
    """VOT-LT long-term ``rows`` (F, Pr, Re, the threshold tau at max F, the sequences scored and of
    them those with absent frames) as a booktabs ``table``, F, Pr and Re marked best bold and second
    underlined as :func:`latex_table` marks scores; the caption ``setting`` (sentences: the experiment,
    the measures) and the trackers ``left_out`` (no or unreadable confidence files). Shrunk to the line if wider
    (graphicx, as the comparison table)."""
    places = {c: _places([r.get(c) for r in rows]) for c in ("f", "precision", "recall")}
    body = []
    for row in rows:
        cells = []
        for c in columns:
            value = row.get(c)
            text = (rf"${'-' if value < 0 else ''}\infty$" if isinstance(value, float) and math.isinf(value)
                    else _number(c, value))
            mark = {1: r"\textbf{%s}", 2: r"\underline{%s}"}.get(places.get(c, {}).get(value))
            cells.append(mark % text if mark else text)
        body.append(" & ".join(cells) + r" \\")
    caption = _sentences(setting) + " Best in bold, second underlined."
    if left_out:
        caption += f" Not scored (confidences missing or unreadable): {escape(', '.join(left_out))}."
    align = "".join("l" if c == "tracker" else "r" for c in columns)
    head = " & ".join(LONG_TERM_HEADERS.get(c, escape(c)) for c in columns) + r" \\"
    return _table(caption, align, [head], body, fit=True)  # tracker names may be long


def _sentences(parts: Seq[str]) -> str:
    """``parts`` escaped, each a sentence (capitalised, a full stop)."""
    out = []
    for part in parts:
        text = escape(part.rstrip(". "))
        out.append(text[:1].upper() + text[1:] + ".")
    return " ".join(out)


# a wide table shrunk to the line only when it is wider (graphicx's \resizebox, \width its own width)
_FIT = r"\resizebox{\ifdim\width>\linewidth\linewidth\else\width\fi}{!}{%"


def _table(caption: str, align: str, head: Seq[str], body: Seq[str], wide: bool = False, fit: bool = False) -> str:
    """A booktabs float; ``wide``: ``table*`` (both columns of a two-column paper), a smaller
    font, narrower column gaps and shrunk to the line if still wider (graphicx), which a
    comparison's 4 columns per score need; ``fit``: a ``table`` shrunk to the line if wider."""
    env, small = ("table*", [r"\small", r"\setlength{\tabcolsep}{3.5pt}"]) if wide else ("table", [])
    end = "}" if wide or fit else ""
    return "\n".join([rf"\begin{{{env}}}", r"\centering", *small, rf"\caption{{{caption}}}",
                      *([_FIT] if wide or fit else []),
                      rf"\begin{{tabular}}{{{align}}}", r"\toprule", *head, r"\midrule", *body, r"\bottomrule",
                      r"\end{tabular}" + end, rf"\end{{{env}}}"]) + "\n"


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
