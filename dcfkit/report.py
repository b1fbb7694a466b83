"""Scores, tables and OTB-style plots from result files.

:func:`evaluate` turns results into plain dicts: one row per tracker (``overall``), per
tracker and sequence (``per_sequence``) and per tracker and attribute
(``per_attribute``), plus the averaged curves for plotting. Scores follow
:mod:`dcfkit.metrics` (OTB toolkit conventions); averages weigh each sequence equally
unless ``weighting="frame"``. A tracker's ``fps`` is the mean over sequences of the
per-sequence fps (frames / tracker time in that sequence), not total frames / total time.
A sequence missing from a tracker's results is scored as a total failure and counted in
the ``missing`` column.
"""
from __future__ import annotations

import argparse
import csv
import io
import json
import logging
import math
from pathlib import Path
from typing import Iterable, Mapping, Sequence as Seq

import numpy as np

from . import metrics
from .datasets import ATTRIBUTE_NAMES, DatasetError, Sequence

__all__ = [
    "add_report_arguments",
    "cmd_report",
    "evaluate",
    "format_rows",
    "gather_results",
    "plot_curves",
    "write_report",
]

log = logging.getLogger(__name__)

OVERALL_COLUMNS = ("tracker", "auc", "precision", "norm_precision", "fps", "sequences", "missing")
SEQUENCE_COLUMNS = ("tracker", "sequence", "auc", "precision", "norm_precision", "fps", "frames")
ATTRIBUTE_COLUMNS = ("attribute", "name", "sequences", "tracker", "auc", "precision", "norm_precision")


# --------------------------------------------------------------------------- scoring


def _boxes_and_fps(result) -> tuple[np.ndarray, float | None]:
    if hasattr(result, "boxes"):
        return np.asarray(result.boxes, dtype=np.float64), getattr(result, "fps", None)
    if isinstance(result, Mapping):
        return np.asarray(result["boxes"], dtype=np.float64), result.get("fps")
    return np.asarray(result, dtype=np.float64), None


def _mean_or_none(values) -> float | None:
    values = [v for v in values if v is not None and math.isfinite(v)]
    return float(np.mean(values)) if values else None


def evaluate(results: Mapping[str, Mapping], sequences: Iterable[Sequence],
             include_first: bool = True, weighting: str = "sequence") -> dict:
    """Score ``results`` (tracker -> sequence name -> boxes) on ``sequences``.

    A result is a :class:`dcfkit.evaluation.SequenceResult`, a dict with ``boxes`` (and
    optional ``fps``) or an ``(N, 4)`` array of 0-based boxes. Returns a plain dict with
    ``overall``, ``per_sequence`` and ``per_attribute`` row lists (trackers sorted by AUC,
    best first), ``curves`` (tracker -> averaged ``precision``/``success``/
    ``norm_precision`` curves), ``attribute_curves`` (attribute -> tracker -> curves),
    ``attributes`` (attribute -> number of sequences) and ``thresholds``.
    """
    sequences = list(sequences)
    per_seq: dict[str, dict[str, dict]] = {}
    fps: dict[str, dict[str, float | None]] = {}
    missing: dict[str, list[str]] = {}
    for tracker, res in results.items():
        per_seq[tracker], fps[tracker], missing[tracker] = {}, {}, []
        for seq in sequences:
            if seq.name in res:
                boxes, seq_fps = _boxes_and_fps(res[seq.name])
                if len(boxes) > len(seq):
                    raise DatasetError(
                        f"tracker {tracker!r}, sequence {seq.name!r}: {len(boxes)} boxes for "
                        f"{len(seq)} frames")
                if len(boxes) < len(seq):
                    log.warning("tracker %r, sequence %r: %d boxes for %d frames; the last %d frames are "
                                "scored as failures", tracker, seq.name, len(boxes), len(seq), len(seq) - len(boxes))
            else:
                boxes, seq_fps = np.empty((0, 4)), None
                missing[tracker].append(seq.name)
            per_seq[tracker][seq.name] = metrics.score_sequence(boxes, seq.ground_truth, include_first)
            fps[tracker][seq.name] = seq_fps
        if missing[tracker]:
            log.warning("tracker %r has no results for %d of %d sequences (scored as failures; "
                        "report on the sequences that were run, e.g. with --sequences, to leave them out): %s",
                        tracker, len(missing[tracker]), len(sequences), ", ".join(missing[tracker][:10]))

    overall, curves = [], {}
    for tracker in results:
        avg = metrics.average(per_seq[tracker].values(), weighting)
        curves[tracker] = _curves(avg)
        overall.append({
            "tracker": tracker, "auc": avg["auc"], "precision": avg["precision"],
            "norm_precision": avg["norm_precision"], "fps": _mean_or_none(fps[tracker].values()),
            "sequences": len(sequences), "missing": len(missing[tracker]), "frames": avg["frames"],
        })
    overall.sort(key=lambda r: _sort_key(r["auc"]))
    ranked = [r["tracker"] for r in overall]

    per_sequence = [
        {"tracker": t, "sequence": s.name, "auc": per_seq[t][s.name]["auc"],
         "precision": per_seq[t][s.name]["precision"],
         "norm_precision": per_seq[t][s.name]["norm_precision"],
         "fps": fps[t][s.name], "frames": per_seq[t][s.name]["frames"]}
        for t in ranked for s in sequences]

    attributes: dict[str, list[str]] = {}
    for seq in sequences:
        for attr, present in seq.attributes.items():
            attributes.setdefault(attr, [])
            if present:
                attributes[attr].append(seq.name)
    per_attribute, attribute_curves = [], {}
    for attr, names in attributes.items():
        if not names:
            continue
        attribute_curves[attr] = {}
        rows = []
        for tracker in ranked:
            avg = metrics.average([per_seq[tracker][n] for n in names], weighting)
            attribute_curves[attr][tracker] = _curves(avg)
            rows.append({"attribute": attr, "name": ATTRIBUTE_NAMES.get(attr, attr),
                         "sequences": len(names), "tracker": tracker, "auc": avg["auc"],
                         "precision": avg["precision"], "norm_precision": avg["norm_precision"]})
        per_attribute += sorted(rows, key=lambda r: _sort_key(r["auc"]))

    return {
        "overall": overall,
        "per_sequence": per_sequence,
        "per_attribute": per_attribute,
        "curves": curves,
        "attribute_curves": attribute_curves,
        "attributes": {a: len(n) for a, n in attributes.items() if n},
        "thresholds": {"precision": metrics.PRECISION_THRESHOLDS,
                       "success": metrics.SUCCESS_THRESHOLDS,
                       "norm_precision": metrics.NORM_PRECISION_THRESHOLDS},
        "settings": {"include_first": include_first, "weighting": weighting},
    }


def _curves(avg: dict) -> dict:
    return {"precision": avg["precision_curve"], "success": avg["success_curve"],
            "norm_precision": avg["norm_precision_curve"], "precision_score": avg["precision"],
            "auc": avg["auc"], "norm_precision_score": avg["norm_precision"]}


def _sort_key(score) -> float:
    return -score if score is not None and math.isfinite(score) else math.inf


# --------------------------------------------------------------------------- tables

_SCORE_COLUMNS = {"auc", "precision", "norm_precision"}


def _cell(key: str, value, full: bool = False) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "" if full else "-"
    if isinstance(value, float):
        if full:
            return repr(value)
        return f"{value:.3f}" if key in _SCORE_COLUMNS else f"{value:.1f}"
    return str(value)


def format_rows(rows: Seq[Mapping], fmt: str = "table", columns: Seq[str] | None = None) -> str:
    """Rows as an aligned text table (``"table"``), ``"markdown"`` or ``"csv"``.

    Scores are shown with 3 decimals and fps with 1 in table/markdown; CSV keeps full
    precision and leaves missing values empty.
    """
    if fmt not in ("table", "markdown", "csv"):
        raise ValueError(f"format must be table, markdown or csv, got {fmt!r}")
    if columns is None:
        columns = list(rows[0]) if rows else []
    if fmt == "csv":
        buf = io.StringIO()
        writer = csv.writer(buf, lineterminator="\n")
        writer.writerow(columns)
        for row in rows:
            writer.writerow([_cell(c, row.get(c), full=True) for c in columns])
        return buf.getvalue()
    cells = [[_cell(c, row.get(c)) for c in columns] for row in rows]
    numeric = [all(_is_number(row.get(c)) for row in rows) and bool(rows) for c in columns]
    if fmt == "markdown":
        lines = ["| " + " | ".join(columns) + " |",
                 "|" + "|".join("---:" if n else ":---" for n in numeric) + "|"]
        lines += ["| " + " | ".join(r) + " |" for r in cells]
        return "\n".join(lines) + "\n"
    widths = [max([len(c)] + [len(r[i]) for r in cells]) for i, c in enumerate(columns)]

    def line(values):
        return "  ".join(v.rjust(w) if n else v.ljust(w)
                         for v, w, n in zip(values, widths, numeric)).rstrip()

    out = [line(columns), "  ".join("-" * w for w in widths)] + [line(r) for r in cells]
    return "\n".join(out) + "\n"


def _is_number(value) -> bool:
    return value is None or (isinstance(value, (int, float)) and not isinstance(value, bool))


# --------------------------------------------------------------------------- plots

_PLOT_STYLE = {
    "precision": dict(title="Precision plots of OPE", xlabel="Location error threshold (pixels)",
                      ylabel="Precision", score="precision_score", loc="lower right"),
    "success": dict(title="Success plots of OPE", xlabel="Overlap threshold",
                    ylabel="Success rate", score="auc", loc="lower left"),
    "norm_precision": dict(title="Normalized precision plots of OPE",
                           xlabel="Normalized location error threshold",
                           ylabel="Normalized precision", score="norm_precision_score",
                           loc="lower right"),
}


def plot_curves(curves: Mapping[str, Mapping], kind: str, path_stem, title: str | None = None,
                formats: Seq[str] = ("png", "svg")) -> list[Path]:
    """OTB-style plot of one curve per tracker; legend ``Name [score]`` sorted by score.

    ``curves`` maps tracker -> the dict of :func:`evaluate`'s ``curves``; ``kind`` is
    ``"precision"`` (score at 20 px), ``"success"`` (AUC) or ``"norm_precision"``.
    Writes ``path_stem.png`` and ``path_stem.svg``; returns the paths.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    style = _PLOT_STYLE[kind]
    x = {"precision": metrics.PRECISION_THRESHOLDS, "success": metrics.SUCCESS_THRESHOLDS,
         "norm_precision": metrics.NORM_PRECISION_THRESHOLDS}[kind]
    fig = Figure(figsize=(5.2, 4.2))
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(1, 1, 1)
    order = sorted(curves, key=lambda t: _sort_key(curves[t][style["score"]]))
    colours = [f"C{i}" for i in range(10)]
    styles = ["-", "--", "-.", ":"]
    for i, tracker in enumerate(order):
        score = curves[tracker][style["score"]]
        label = f"{tracker} [{score:.3f}]" if score is not None and math.isfinite(score) else f"{tracker} [-]"
        ax.plot(x, curves[tracker][kind], color=colours[i % 10], linestyle=styles[(i // 10) % 4],
                linewidth=2.0 if i < 10 else 1.5, label=label)
    ax.set_xlim(x[0], x[-1])
    ax.set_ylim(0, 1)
    ax.set_title(title or style["title"])
    ax.set_xlabel(style["xlabel"])
    ax.set_ylabel(style["ylabel"])
    ax.grid(True, linestyle=":", linewidth=0.6)
    if order:
        ax.legend(loc=style["loc"], fontsize=8, framealpha=0.9)
    fig.tight_layout()
    paths = []
    for ext in formats:
        path = Path(f"{path_stem}.{ext}")
        fig.savefig(path, dpi=150)
        paths.append(path)
    return paths


# --------------------------------------------------------------------------- report


def gather_results(out_dir, sequences: Seq[Sequence], trackers: Iterable[str] | None = None,
                   exclude: Iterable[Path] = ()) -> dict[str, dict]:
    """Results of ``trackers`` for a report: tracker name -> sequence -> result.

    A tracker is a sub-folder name of ``out_dir`` or a path to a folder of result files.
    Folders written by :func:`dcfkit.evaluation.run_one_pass` (with ``.json`` sidecars)
    are read with ``load_results`` (completed sequences only, timings included); other
    folders are imported as plain 1-based ``x,y,w,h`` text files. ``None`` takes every
    sub-folder of ``out_dir`` holding a ``<sequence>.txt`` of one of ``sequences``.
    """
    from .evaluation import import_results, load_results

    out_dir = Path(out_dir)
    exclude = {Path(p).resolve() for p in exclude}
    names = {s.name for s in sequences}
    if trackers is None:
        if not out_dir.is_dir():
            raise DatasetError(f"results folder not found: {out_dir}")
        trackers = [p.name for p in sorted(out_dir.iterdir())
                    if p.is_dir() and not p.name.startswith(".") and p.resolve() not in exclude
                    and any((p / f"{n}.txt").is_file() for n in names)]
    results = {}
    for tracker in trackers:
        folder = out_dir / tracker if (out_dir / tracker).is_dir() else Path(tracker)
        if not folder.is_dir():
            raise DatasetError(f"no results for tracker {tracker!r}: neither {out_dir / tracker} "
                               f"nor {tracker} is a folder")
        if any((folder / f"{n}.json").is_file() for n in names):
            res = load_results(folder.parent, folder.name, sequences)
        else:
            res = {k: v for k, v in import_results(folder).items() if k in names}
        results[folder.name] = res
    return results


def _json_ready(obj):
    if isinstance(obj, dict):
        return {k: _json_ready(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_json_ready(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return [_json_ready(v) for v in obj.tolist()]
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


def _write(evaluation: dict, report_dir: Path) -> list[Path]:
    from .evaluation import make_dir

    make_dir(report_dir)
    paths = []

    def text(name, content):
        path = report_dir / name
        path.write_text(content, encoding="utf-8")
        paths.append(path)

    tables = [("overall", evaluation["overall"], OVERALL_COLUMNS),
              ("per_sequence", evaluation["per_sequence"], SEQUENCE_COLUMNS)]
    if evaluation["per_attribute"]:
        tables.append(("per_attribute", evaluation["per_attribute"], ATTRIBUTE_COLUMNS))
    for stem, rows, cols in tables:
        text(f"{stem}.txt", format_rows(rows, "table", cols))
        text(f"{stem}.md", format_rows(rows, "markdown", cols))
        text(f"{stem}.csv", format_rows(rows, "csv", cols))
    text("report.json", json.dumps(_json_ready(evaluation), indent=1) + "\n")
    for kind in ("precision", "success"):
        paths += plot_curves(evaluation["curves"], kind, report_dir / kind)
    for attr, curves in evaluation["attribute_curves"].items():
        n = evaluation["attributes"][attr]
        title = f"Success plots of OPE - {ATTRIBUTE_NAMES.get(attr, attr)} ({n})"
        paths += plot_curves(curves, "success", report_dir / f"success_{attr}", title=title)
    return paths


def write_report(out_dir, sequences: Seq[Sequence], trackers: Iterable[str] | None = None,
                 report_dir=None, include_first: bool = True, weighting: str = "sequence") -> list[Path]:
    """Score every tracker in ``out_dir`` and write tables and plots to ``report_dir``.

    ``report_dir`` defaults to ``out_dir/report``. Writes ``overall``, ``per_sequence``
    and (when sequences have attributes) ``per_attribute`` tables as ``.txt``, ``.md`` and
    ``.csv``; ``report.json`` with all rows and curves; ``precision`` and ``success`` plots
    and one ``success_<ATTR>`` plot per attribute, each as PNG and SVG. Returns the paths.
    """
    return _report(out_dir, sequences, trackers, report_dir, include_first, weighting)[1]


def _report(out_dir, sequences, trackers, report_dir, include_first=True, weighting="sequence"):
    out_dir = Path(out_dir)
    report_dir = Path(report_dir) if report_dir is not None else out_dir / "report"
    results = gather_results(out_dir, sequences, trackers, exclude=[report_dir])
    if not results:
        raise DatasetError(f"no tracker results found under {out_dir}")
    evaluation = evaluate(results, sequences, include_first, weighting)
    return evaluation, _write(evaluation, report_dir)


# --------------------------------------------------------------------------- CLI


def add_report_arguments(parser: argparse.ArgumentParser) -> argparse.ArgumentParser:
    """Arguments of ``dcfkit report``."""
    parser.add_argument("out", type=Path, metavar="OUT", help="results folder of `dcfkit eval`")
    parser.add_argument("--dataset", default="auto", help="dataset name (default: detect from --root)")
    parser.add_argument("--root", required=True, type=Path, help="benchmark root folder")
    parser.add_argument("--sequences", default=None, help="comma-separated sequence names (default: all)")
    parser.add_argument("--trackers", default=None,
                        help="comma-separated tracker folders (names in OUT or paths; default: all)")
    parser.add_argument("--format", choices=("table", "markdown", "csv"), default="table",
                        help="format of the table printed to stdout")
    parser.add_argument("--report-dir", type=Path, default=None, help="default: OUT/report")
    parser.add_argument("--skip-first", action="store_true",
                        help="do not score frame 0 (default: scored, as the OTB toolkit)")
    parser.add_argument("--frame-weighted", action="store_true",
                        help="average over frames instead of sequences")
    return parser


def cmd_report(args: argparse.Namespace) -> int:
    """``dcfkit report``: print the overall table and write the report files."""
    from .datasets import load_dataset

    sequences = load_dataset(args.dataset, args.root, args.sequences)
    trackers = [t for t in args.trackers.split(",") if t] if args.trackers else None
    evaluation, paths = _report(args.out, sequences, trackers, args.report_dir,
                                include_first=not args.skip_first,
                                weighting="frame" if args.frame_weighted else "sequence")
    print(format_rows(evaluation["overall"], args.format, OVERALL_COLUMNS), end="")
    if args.format == "table":
        print(f"\n{len(paths)} files written to {paths[0].parent}")
    return 0
