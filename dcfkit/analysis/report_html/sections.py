"""The sections of a report page as plain data (``report.js`` draws them): tables, line
charts, the sequence gallery and the provenance.

Trackers are numbered by their place in the page's ``trackers`` list; a series or a box of
tracker ``i`` gets its colour and its legend toggle (key ``t<i>``) from that number, so a
tracker looks the same in every plot and thumbnail.
"""
from __future__ import annotations

import math
from pathlib import Path
from typing import Iterable, Mapping
from typing import Sequence as Seq

from dcfkit.analysis.longterm_report import LONG_TERM_COLUMNS, MEASURES
from dcfkit.analysis.plots import PLOT_STYLE, plot_title
from dcfkit.analysis.report_html.provenance import folder_provenance
from dcfkit.analysis.report_html.thumbnails import sequence_thumbnails
from dcfkit.analysis.stats.columns import DIFFERENCE, MEAN, fill, shown
from dcfkit.analysis.stats.results import Comparison
from dcfkit.analysis.tables import SCORE_LABELS, statistics_scope
from dcfkit.datasets import ATTRIBUTE_NAMES, Sequence

COLUMN_LABELS = {**SCORE_LABELS, "norm_precision": "norm. precision", "fps": "fps", "sequences": "sequences",
                 "missing": "missing", "frames": "frames", "failed": "failed", "key": "run key",
                 "name": "attribute name"}
TEXT_COLUMNS = ("sequence", "attribute", "name", "status", "key", "variant", "reason")
LONG_TERM_LABELS = {"tracker": "tracker", "f": "F", "precision": "Pr", "recall": "Re", "threshold": "\u03c4 at max F",
                    "sequences": "sequences", "absent": "sequences with absent frames", "reason": "why"}


def _column(key: str, tracker_column: str, labels: Mapping[str, str] | None = None) -> dict:
    kind = "tracker" if key == tracker_column else "text" if key in TEXT_COLUMNS else "num"
    digits = 1 if key == "fps" else 0 if key in ("sequences", "missing", "frames", "failed", "absent") else 3
    return {"key": key, "label": (labels or COLUMN_LABELS).get(key, key), "type": kind, "digits": digits}


def count(n: int, noun: str) -> str:
    """``1 tracker``, ``3 trackers``."""
    return f"{n} {noun}{'' if n == 1 else 's'}"


def table(section_id: str, title: str, rows: Seq[Mapping], columns: Seq[str], trackers: Seq[str],
          tracker_column: str = "tracker", filterable: bool = False, note: str = "",
          labels: Mapping[str, str] | None = None) -> dict:
    """A sortable table (``filterable``: with a filter box) of ``rows`` (dicts) in ``columns``
    headed by ``labels`` (default :data:`COLUMN_LABELS`); the ``tracker_column`` holds tracker
    numbers, drawn with their colour."""
    index = {t: i for i, t in enumerate(trackers)}
    cols = [_column(c, tracker_column, labels) for c in columns]
    cells = [[index[r[c]] if c == tracker_column else r.get(c) for c in columns] for r in rows]
    return {"kind": "table", "id": section_id, "title": title, "columns": cols, "rows": cells,
            "filter": filterable, "note": note}


def _score(value) -> str:
    return f"{value:.3f}" if value is not None and math.isfinite(value) else "-"


def curve_chart(kind: str, curves: Mapping[str, Mapping], thresholds, trackers: Seq[str], title: str | None = None,
                small: bool = False) -> dict:
    """One OTB plot (``kind`` precision, success or norm_precision): a series per tracker,
    best score first, labelled ``name [score]`` as :func:`dcfkit.analysis.plots.plot_curves` does."""
    style = PLOT_STYLE[kind]
    score = {t: curves[t][style["score"]] for t in curves}
    scored = sorted(curves, key=lambda t: -score[t] if _finite(score[t]) else math.inf)
    series = [{"key": f"t{trackers.index(t)}", "t": trackers.index(t),
               "label": f"{t} [{_score(curves[t][style['score']])}]", "y": curves[t][kind]} for t in scored]
    return {"title": title or style["title"], "xlabel": style["xlabel"], "ylabel": style["ylabel"],
            "x": thresholds, "ylim": [0, 1], "series": series, "small": small}


def _finite(value) -> bool:
    return value is not None and math.isfinite(value)


def curve_charts(evaluation: Mapping, trackers: Seq[str]) -> dict:
    """The success, precision and normalized precision plots of all sequences."""
    experiment = evaluation.settings.get("experiment", "ope")  # TRE's pooled runs are not OPE's
    charts = [curve_chart(kind, evaluation.curves, evaluation.thresholds[kind], trackers,
                          title=plot_title(kind, experiment))
              for kind in ("success", "precision", "norm_precision")]
    return {"kind": "charts", "id": "plots", "title": "Success and precision plots", "charts": charts}


def attribute_charts(evaluation: Mapping, trackers: Seq[str]) -> dict | None:
    """One small success plot per attribute, or None when the sequences have none."""
    if not evaluation.attribute_curves:
        return None
    charts = [curve_chart("success", curves, evaluation.thresholds["success"], trackers, small=True,
                          title=f"{ATTRIBUTE_NAMES.get(attr, attr)} ({evaluation.attributes[attr]})")
              for attr, curves in evaluation.attribute_curves.items()]
    return {"kind": "charts", "id": "attribute-plots", "title": "Success plots per attribute", "charts": charts}


def long_term(record: Mapping, trackers: Seq[str]) -> dict | None:
    """The VOT-LT measures of a report (:func:`dcfkit.analysis.longterm_report.score_long_term`): the
    table, the trackers left out and why, and each tracker's averaged precision-recall curve (Pr
    against Re over the thresholds) with its maximum F marked; the reason alone for an experiment
    that has none (TRE, SRE); None without long-term scores."""
    title = "Long-term measures"
    if "skipped" in record:
        return {"kind": "group", "id": "long-term", "title": title, "note": _sentence(record["skipped"]), "parts": []}
    if not record.get("rows"):
        return None
    rows = [{**r, "threshold": r["threshold"] if math.isfinite(r["threshold"]) else str(r["threshold"])}
            for r in record["rows"]]  # -inf (every frame present) shown as the text table shows it
    parts = [table("long-term", "", rows, LONG_TERM_COLUMNS, trackers, labels=LONG_TERM_LABELS)]  # the section's
    if record["left_out"]:
        parts.append(table("long-term-left-out", "No long-term scores",
                           [{"tracker": t, "reason": why} for t, why in record["left_out"].items()],
                           ("tracker", "reason"), trackers, labels=LONG_TERM_LABELS))
    parts.append({"kind": "charts", "charts": [_precision_recall(record, trackers)],
                  "note": "Pr and Re averaged over the sequences at each threshold \u03c4; a dot marks each "
                          "tracker's maximum F, the number after its name."})
    note = _sentence(MEASURES)
    if record.get("unbounded"):
        names = record["unbounded"]
        note += (f" The overlaps of {count(len(names), 'sequence')} are the continuous IoU, not bounded by the image "
                 f"(their frame 1 cannot be read): {', '.join(names[:10])}{' ...' if len(names) > 10 else ''}.")
    return {"kind": "group", "id": "long-term", "title": title, "note": note, "parts": parts}


def _sentence(text: str) -> str:
    return text[:1].upper() + text[1:] + ("" if text.endswith(".") else ".")


def _precision_recall(record: Mapping, trackers: Seq[str]) -> dict:
    """Each tracker's averaged Pr against Re, best F first, its maximum F's point marked."""
    series = []
    for row in record["rows"]:
        t, curve = row["tracker"], record["curves"][row["tracker"]]
        series.append({"key": f"t{trackers.index(t)}", "t": trackers.index(t), "label": f"{t} [{_score(row['f'])}]",
                       "x": curve["recall"], "y": curve["precision"], "point": [row["recall"], row["precision"]]})
    return {"title": "Tracking precision-recall plot of OPE", "xlabel": "Tracking recall (Re)",
            "ylabel": "Tracking precision (Pr)", "x": None, "xlim": [0, 1], "ylim": [0, 1], "series": series,
            "small": False}


def gallery(sequences: Seq[Sequence], results: Mapping[str, Mapping], trackers: Seq[str],
            per_sequence: Seq[Mapping], tracker_column: str = "tracker") -> dict:
    """Per sequence: its attributes, each tracker's AUC and the thumbnails of
    :mod:`~dcfkit.analysis.report_html.thumbnails` (frame 1 and the worst frame of each third)."""
    auc = {(r[tracker_column], r["sequence"]): r["auc"] for r in per_sequence}
    cards = [{"name": s.name, "frames": len(s), "attributes": [a for a, on in s.attributes.items() if on],
              "auc": [auc.get((t, s.name)) for t in trackers],
              "thumbs": sequence_thumbnails(s, results, trackers)} for s in sequences]
    return {"kind": "gallery", "id": "frames", "title": "Frames",
            "note": "Frame 1 whole, then in each third of the sequence the frame where the trackers overlap the "
                    "ground truth least on average, zoomed to the boxes. White: ground truth.", "cards": cards}


def provenance(folders: Mapping[str, Path], names: Iterable[str], trackers: Seq[str], this_run: Mapping,
               extra: Seq[tuple[str, str]] = (), base: Path | None = None) -> dict:
    """What produced the results of each tracker (its folder's sidecars, paths relative to
    ``base``, the page's folder) and this page."""
    names = list(names)
    entries = [{"t": trackers.index(t), **folder_provenance(folder, names, base)} for t, folder in folders.items()]
    return {"kind": "provenance", "id": "provenance", "title": "Provenance", "report": dict(this_run),
            "extra": [list(e) for e in extra], "trackers": entries}


def statistics_table(statistics: Comparison | Mapping, trackers: Seq[str], tracker_label: str = "tracker") -> dict | None:
    """A :class:`~dcfkit.analysis.stats.results.Comparison` as a table: per score the columns
    declared for ``html`` (:mod:`dcfkit.analysis.stats.columns`: each tracker's score with its
    interval and its difference from the baseline, drawn as bars, '*' where significant after
    Holm's correction, and the corrected p); the method as its note."""
    if not statistics:
        return None
    names = list(statistics.means)
    columns = [{"key": "tracker", "label": tracker_label, "type": "tracker", "digits": 0}]
    rows = [[trackers.index(t)] for t in names]
    for key in statistics.scores:
        label = COLUMN_LABELS.get(key, key)
        found = {MEAN: [statistics.means[t][key] for t in names],
                 DIFFERENCE: [statistics.differences.get(t, {}).get(key) for t in names]}
        for level, results in found.items():
            for _, cell in shown(level, "html"):
                values = [None if r is None else cell.render(r, key) for r in results]
                columns.append(_stat_column(cell, level, fill(cell.key, score=key),
                                            fill(cell.header, score=label, baseline=statistics.baseline), values))
                for row, value in zip(rows, values):
                    row.append(value)
    over, left_out = statistics_scope(statistics)
    note = " ".join([f"Over {over} sequences every tracker ran: {statistics.method}; {statistics.correction} "
                     f"(marked *)."] + [f"{line[0].upper()}{line[1:]}." for line in left_out])
    return {"kind": "table", "id": "statistics", "title": "Confidence and significance", "columns": columns,
            "rows": rows, "filter": False, "note": note}


def _stat_column(cell, level: str, key: str, label: str, values: Seq) -> dict:
    """A statistic's column; one of intervals (``[mean, low, high, significant]``) on a common
    scale: from the lowest to the highest bound (and 0 for differences, whose bars are read
    against it)."""
    if cell.kind != "interval":
        return {"key": key, "label": label, "type": cell.kind, "digits": 3}
    bounds = [v for value in values if value for v in value[:3] if v is not None]
    if level == DIFFERENCE:
        bounds.append(0.0)
    low, high = (min(bounds), max(bounds)) if bounds else (0.0, 1.0)
    return {"key": key, "label": label, "type": "interval", "digits": 3, "domain": [low, high]}
