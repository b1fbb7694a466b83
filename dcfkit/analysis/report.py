"""Scores, tables and OTB-style plots from result files.

:func:`evaluate` turns results into plain dicts: one row per tracker (``overall``), per
tracker and sequence (``per_sequence``) and per tracker and attribute
(``per_attribute``), plus the averaged curves for plotting. Scores follow a named scoring
protocol of :mod:`dcfkit.analysis.protocols` (default ``otb``, the OTB / UAV123 MATLAB toolkit),
and every output names it: a first line of the text and Markdown tables, a ``protocol``
column of the CSV tables, ``protocol`` in ``report.json`` and the plot titles. Averages
weigh sequences as the protocol does unless ``weighting`` says otherwise. A tracker's
``fps`` is the mean over sequences of the per-sequence fps (frames / tracker time in that
sequence), not total frames / total time. A sequence missing from a tracker's results is
scored as a total failure and counted in the ``missing`` column. :mod:`dcfkit.analysis.report_html`
adds one self-contained HTML page of it all (``dcfkit report --html``).
"""
from __future__ import annotations

import csv
import io
import json
import logging
import math
import os
from collections import Counter
from pathlib import Path
from typing import Iterable, Mapping
from typing import Sequence as Seq

import numpy as np

from dcfkit.analysis import metrics
from dcfkit.analysis.protocols import DEFAULT, Protocol, get_protocol
from dcfkit.datasets import ATTRIBUTE_NAMES, DatasetError, Sequence, benchmark_protocol, scored_sequences
from dcfkit.errors import clip, shown
from dcfkit.running import platforms
from dcfkit.running.files import atomic_write, ensure_writable
from dcfkit.running.results import import_results, load_results

__all__ = [
    "columns",
    "default_report_dir",
    "evaluate",
    "format_rows",
    "format_table",
    "gather_results",
    "json_ready",
    "plot_curves",
    "read_folder",
    "score_and_write",
    "score_folders",
    "score_line",
    "tracker_folders",
    "write_files",
    "write_report",
]

log = logging.getLogger(__name__)

_TABLES = {  # the columns before and after a protocol's scores (Protocol.score_keys)
    "overall": (("tracker",), ("fps", "sequences", "missing")),
    "per_sequence": (("tracker", "sequence"), ("fps", "frames")),
    "per_attribute": (("attribute", "name", "sequences", "tracker"), ()),
}


def columns(table: str, protocol: str | Protocol = DEFAULT) -> tuple[str, ...]:
    """Columns of the ``overall``, ``per_sequence`` or ``per_attribute`` table under ``protocol``."""
    lead, tail = _TABLES[table]
    return lead + get_protocol(protocol).score_keys + tail


OVERALL_COLUMNS = columns("overall")
SEQUENCE_COLUMNS = columns("per_sequence")
ATTRIBUTE_COLUMNS = columns("per_attribute")


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
             include_first: bool = True, weighting: str | None = None,
             protocol: str | Protocol | None = None) -> dict:
    """Score ``results`` (tracker -> sequence name -> boxes) on ``sequences`` under ``protocol``
    (by default the rules of the benchmark's published tables,
    :func:`~dcfkit.datasets.benchmark_protocol`: LaSOT's for LaSOT, the OTB toolkit's for UAV123).

    A result is a :class:`dcfkit.running.results.SequenceResult`, a dict with ``boxes`` (and
    optional ``fps``) or an ``(N, 4)`` array of 0-based boxes. ``weighting`` ``None`` averages
    as the protocol does. Returns a plain dict with ``overall``, ``per_sequence`` and
    ``per_attribute`` row lists (trackers best first by the protocol's ranking score: AO for
    ``got10k``, else AUC), ``curves`` (tracker -> averaged ``precision``/``success``/
    ``norm_precision`` curves), ``attribute_curves`` (attribute -> tracker -> curves),
    ``attributes`` (attribute -> number of sequences), ``thresholds``, ``protocol`` (name,
    title, source), ``settings`` and ``platforms`` (tracker -> ``[[platform, sequences], ...]``
    of :func:`dcfkit.running.platforms.describe`). Sequences whose ground truth is withheld after
    frame 1 (test splits) are left out (:func:`~dcfkit.datasets.scored_sequences`: a
    :class:`DatasetError` if that leaves none).
    """
    sequences = list(sequences)
    proto = get_protocol(protocol or benchmark_protocol(sequences))
    weighting = weighting or proto.weighting
    keys = proto.score_keys
    sequences = scored_sequences(sequences)
    per_seq, fps, missing = {}, {}, {}
    for tracker, res in results.items():
        per_seq[tracker], fps[tracker], missing[tracker] = _score_tracker(tracker, res, sequences, include_first,
                                                                          proto)

    overall, curves = [], {}
    for tracker in results:
        avg = metrics.average(per_seq[tracker].values(), weighting, proto)
        curves[tracker] = _curves(avg)
        overall.append({"tracker": tracker, **{k: avg[k] for k in keys},
                        "fps": _mean_or_none(fps[tracker].values()),
                        "sequences": len(sequences), "missing": len(missing[tracker]), "frames": avg["frames"]})
    overall = _rank(overall, proto)
    ranked = [r["tracker"] for r in overall]
    per_sequence = [
        {"tracker": t, "sequence": s.name, **{k: per_seq[t][s.name][k] for k in keys},
         "fps": fps[t][s.name], "frames": per_seq[t][s.name]["frames"]}
        for t in ranked for s in sequences]
    attributes = _attribute_members(sequences)
    per_attribute, attribute_curves = _per_attribute(attributes, per_seq, ranked, weighting, proto)
    return {
        "protocol": {"name": proto.name, "title": proto.title, "source": proto.source},
        "overall": overall,
        "per_sequence": per_sequence,
        "per_attribute": per_attribute,
        "curves": curves,
        "attribute_curves": attribute_curves,
        "attributes": {a: len(n) for a, n in attributes.items()},
        "thresholds": _thresholds(proto),
        "settings": {"protocol": proto.name, "include_first": include_first, "weighting": weighting},
        "platforms": {t: _platforms(res.values()) for t, res in results.items()},
    }


def _platforms(results: Iterable) -> list[list]:
    """``[[platform line, sequences], ...]`` of one tracker's results (imports: none recorded)."""
    return [[line, n] for line, n in Counter(
        platforms.describe(getattr(r, "platform", None)) for r in results).most_common()]


def _score_tracker(tracker: str, res: Mapping, sequences: list[Sequence], include_first: bool,
                   proto: Protocol) -> tuple[dict, dict, list]:
    """(sequence -> scores, sequence -> fps, missing sequence names) of one tracker's results."""
    scores, fps, missing = {}, {}, []
    for seq in sequences:
        if seq.name in res:
            boxes, fps[seq.name] = _boxes_and_fps(res[seq.name])
            if len(boxes) > len(seq):
                raise DatasetError(f"tracker {shown(tracker)}, sequence {seq.name!r}: {len(boxes)} boxes for "
                                   f"{len(seq)} frames")
            if len(boxes) < len(seq):
                log.warning("tracker %r, sequence %r: %d boxes for %d frames; the last %d frames are "
                            "scored as failures", tracker, seq.name, len(boxes), len(seq), len(seq) - len(boxes))
        else:
            boxes, fps[seq.name] = np.empty((0, 4)), None
            missing.append(seq.name)
        scores[seq.name] = metrics.score_sequence(boxes, seq.ground_truth, include_first, proto)
    if missing:
        log.warning("tracker %r has no results for %d of %d sequences (scored as failures; "
                    "report on the sequences that were run, e.g. with --sequences, to leave them out): %s",
                    tracker, len(missing), len(sequences), ", ".join(missing[:10]))
    return scores, fps, missing


def _rank(rows: list[dict], proto: Protocol) -> list[dict]:
    return sorted(rows, key=lambda r: _sort_key(r[proto.rank_key]))


def _attribute_members(sequences: list[Sequence]) -> dict[str, list[str]]:
    """attribute -> the sequences that have it (attributes no sequence has are left out)."""
    members: dict[str, list[str]] = {}
    for seq in sequences:
        for attr, present in seq.attributes.items():
            members.setdefault(attr, [])
            if present:
                members[attr].append(seq.name)
    return {a: names for a, names in members.items() if names}


def _per_attribute(attributes: dict, per_seq: dict, ranked: list[str], weighting: str,
                   proto: Protocol) -> tuple[list[dict], dict]:
    """Rows (per attribute, trackers ranked) and curves of the scores averaged per attribute."""
    per_attribute, attribute_curves = [], {}
    for attr, names in attributes.items():
        attribute_curves[attr] = {}
        rows = []
        for tracker in ranked:
            avg = metrics.average([per_seq[tracker][n] for n in names], weighting, proto)
            attribute_curves[attr][tracker] = _curves(avg)
            rows.append({"attribute": attr, "name": ATTRIBUTE_NAMES.get(attr, attr),
                         "sequences": len(names), "tracker": tracker, **{k: avg[k] for k in proto.score_keys}})
        per_attribute += _rank(rows, proto)
    return per_attribute, attribute_curves


def _thresholds(proto: Protocol) -> dict[str, np.ndarray]:
    return {"precision": proto.precision_thresholds, "success": proto.success_thresholds,
            "norm_precision": proto.norm_precision_thresholds}


def _curves(avg: dict) -> dict:
    return {"precision": avg["precision_curve"], "success": avg["success_curve"],
            "norm_precision": avg["norm_precision_curve"], "precision_score": avg["precision"],
            "auc": avg["auc"], "norm_precision_score": avg["norm_precision"]}


def _sort_key(score) -> float:
    return -score if score is not None and math.isfinite(score) else math.inf


# --------------------------------------------------------------------------- tables

def _cell(key: str, value, full: bool = False) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "" if full else "-"
    if isinstance(value, float):
        if full:
            return repr(value)
        return f"{value:.1f}" if key == "fps" else f"{value:.3f}"
    if full:
        return str(value)
    # a sequence or tracker is named by a folder, whose name may hold a line break or a '|'
    return "".join(c if c.isprintable() else c.encode("unicode_escape").decode() for c in str(value))


def format_rows(rows: Seq[Mapping], fmt: str = "table", columns: Seq[str] | None = None) -> str:
    """Rows as an aligned text table (``"table"``), ``"markdown"`` or ``"csv"``.

    Floats are shown with 3 decimals (fps with 1) in table/markdown; CSV keeps full
    precision and leaves missing values empty.
    """
    if fmt not in ("table", "markdown", "csv"):
        raise ValueError(f"format must be table, markdown or csv, got {shown(fmt)}")
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
        lines += ["| " + " | ".join(c.replace("|", "\\|") for c in r) + " |" for r in cells]
        return "\n".join(lines) + "\n"
    widths = [max([len(c)] + [len(r[i]) for r in cells]) for i, c in enumerate(columns)]

    def line(values):
        return "  ".join(v.rjust(w) if n else v.ljust(w)
                         for v, w, n in zip(values, widths, numeric)).rstrip()

    out = [line(columns), "  ".join("-" * w for w in widths)] + [line(r) for r in cells]
    return "\n".join(out) + "\n"


def _is_number(value) -> bool:
    return value is None or (isinstance(value, (int, float)) and not isinstance(value, bool))


#: how scores are named in text (a score key of :class:`~dcfkit.analysis.protocols.Protocol` -> its name)
SCORE_LABELS = {"ao": "AO", "sr50": "SR@0.5", "sr75": "SR@0.75", "auc": "AUC", "precision": "precision",
                "norm_precision": "normalized precision"}


def score_line(row: Mapping, protocol: str | Protocol = DEFAULT) -> str:
    """One overall row as ``precision 0.891, AUC 0.520 on 6 sequences (protocol otb)``."""
    proto = get_protocol(protocol)
    scores = ", ".join(f"{SCORE_LABELS[k]} {_cell(k, row[k])}" for k in proto.score_keys)
    return f"{scores} on {row['sequences']} sequences (protocol {proto.name})"


def format_table(rows: Seq[Mapping], fmt: str, columns: Seq[str], protocol: str | Protocol = DEFAULT) -> str:
    """:func:`format_rows` naming the scoring protocol: a first line (``table``,
    ``markdown``) or a last ``protocol`` column (``csv``, so the file stays one table)."""
    proto = get_protocol(protocol)
    if fmt == "csv":
        return format_rows([{**r, "protocol": proto.name} for r in rows], fmt, (*columns, "protocol"))
    return f"{proto.describe()}\n\n" + format_rows(rows, fmt, columns)


# --------------------------------------------------------------------------- plots

#: title, axis labels, score and legend place of the plots of each curve kind
PLOT_STYLE = {
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
                formats: Seq[str] = ("png", "svg"), protocol: str | Protocol = DEFAULT) -> list[Path]:
    """OTB-style plot of one curve per tracker; legend ``Name [score]`` sorted by score.

    ``curves`` maps tracker -> the dict of :func:`evaluate`'s ``curves`` (computed under
    ``protocol``, whose thresholds are the x axis and whose name ends the title); ``kind``
    is ``"precision"`` (score at 20 px), ``"success"`` (AUC) or ``"norm_precision"``.
    Writes ``path_stem.png`` and ``path_stem.svg``; returns the paths.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg  # lazy: matplotlib is slow to import,
    from matplotlib.figure import Figure  # and only plots need it

    proto = get_protocol(protocol)
    style = PLOT_STYLE[kind]
    x = _thresholds(proto)[kind]
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
    ax.set_title(f"{title or style['title']} [protocol {proto.name}]")
    ax.set_xlabel(style["xlabel"])
    ax.set_ylabel(style["ylabel"])
    ax.grid(True, linestyle=":", linewidth=0.6)
    if order:
        ax.legend(loc=style["loc"], fontsize=8, framealpha=0.9)
    fig.tight_layout()
    paths = [Path(f"{path_stem}.{ext}") for ext in formats]
    for path in paths:
        save_figure(fig, path)
    return paths


def save_figure(fig, path: Path) -> None:
    """Render a matplotlib figure (format from the suffix) and write it atomically."""
    buffer = io.BytesIO()
    fig.savefig(buffer, format=path.suffix[1:], dpi=150)
    atomic_write(path, buffer.getvalue())


# --------------------------------------------------------------------------- report


def gather_results(out_dir, sequences: Seq[Sequence], trackers: Iterable[str] | None = None,
                   exclude: Iterable[Path] = ()) -> dict[str, dict]:
    """Results of ``trackers`` for a report: tracker name -> sequence -> result.

    Trackers and their names are those of :func:`tracker_folders`. Folders written by
    :func:`dcfkit.running.evaluation.run_one_pass` (with ``.json`` sidecars) are read with
    ``load_results`` (intact results only, timings included); other folders are imported as
    plain 1-based ``x,y,w,h`` text files.
    """
    return {name: read_folder(folder, sequences)
            for name, folder in tracker_folders(out_dir, sequences, trackers, exclude).items()}


def read_folder(folder: Path, sequences: Seq[Sequence]) -> dict:
    """Sequence name -> result of the tracker in ``folder`` (see :func:`gather_results`)."""
    names = {s.name for s in sequences}
    if any((folder / f"{n}.json").is_file() for n in names):
        return load_results(folder.parent, folder.name, sequences)
    return {k: v for k, v in import_results(folder).items() if k in names}


def tracker_folders(out_dir, sequences: Seq[Sequence], trackers: Iterable[str] | None = None,
                    exclude: Iterable[Path] = ()) -> dict[str, Path]:
    """Tracker name -> results folder, for a report on ``sequences``.

    A tracker is a sub-folder name of ``out_dir`` or a path to a folder of result files.
    ``None`` takes every sub-folder of ``out_dir`` holding a ``<sequence>.txt`` of one of
    ``sequences``, except the folders in ``exclude`` that hold no tracker results (a
    report's own folder). A tracker is named by its folder's name, or by ``parent/name``
    where two folders share a name (``reference_results/BACF/UAV123_10fps`` and
    ``.../DR2Track/UAV123_10fps``).
    """
    out_dir = Path(out_dir)
    exclude = {Path(p).resolve() for p in exclude}
    names = {s.name for s in sequences}
    if trackers is None:
        if not out_dir.is_dir():
            raise DatasetError(f"results folder not found: {clip(str(out_dir))}")
        trackers = [p.name for p in sorted(out_dir.iterdir())
                    if p.is_dir() and not p.name.startswith(".") and any((p / f"{n}.txt").is_file() for n in names)
                    and (p.resolve() not in exclude or _holds_results(p, names))]
    folders: dict[Path, Path] = {}
    for tracker in trackers:
        # os.path.isdir: a name too long for the file system is no folder (Path.is_dir raises)
        folder = out_dir / tracker if os.path.isdir(out_dir / tracker) else Path(tracker)
        if not os.path.isdir(folder):
            raise DatasetError(f"no results for tracker {shown(tracker)}: neither {clip(str(out_dir / tracker))} "
                               f"nor {clip(tracker)} is a folder")
        folders.setdefault(folder.resolve(), folder)
    shared = {name for name in (f.name for f in folders.values())
              if sum(g.name == name for g in folders.values()) > 1}
    return {f"{folder.resolve().parent.name}/{folder.name}" if folder.name in shared else folder.name: folder
            for folder in folders.values()}


def _holds_results(folder: Path, names: set[str]) -> bool:
    """Whether ``folder`` has a result file or sidecar of a sequence (a report folder has none)."""
    return any((folder / f"{n}.txt").is_file() or (folder / f"{n}.json").is_file() for n in names)


def json_ready(obj):
    """``obj`` with arrays as lists and non-finite floats as None, for ``json.dumps``."""
    if isinstance(obj, dict):
        return {k: json_ready(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [json_ready(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return [json_ready(v) for v in obj.tolist()]
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


REPORT_TABLES = ("overall", "per_sequence", "per_attribute")
TABLE_FORMATS = (("table", "txt"), ("markdown", "md"), ("csv", "csv"))


def report_file_names(sequences: Seq[Sequence]) -> list[str]:
    """Every file a report on ``sequences`` may write."""
    attributes = sorted({a for s in sequences for a, present in s.attributes.items() if present})
    plots = ["precision", "success"] + [f"success_{a}" for a in attributes]
    return ([f"{t}.{ext}" for t in REPORT_TABLES for _, ext in TABLE_FORMATS] + ["report.json", "report.html"]
            + [f"{p}.{ext}" for p in plots for ext in ("png", "svg")])


def write_files(evaluation: dict, report_dir: Path) -> list[Path]:
    """The tables, ``report.json`` and plots of :func:`write_report` from ``evaluation``."""
    paths = []
    protocol = evaluation["protocol"]["name"]

    def text(name, content):
        path = report_dir / name
        atomic_write(path, content)
        paths.append(path)

    tables = REPORT_TABLES if evaluation["per_attribute"] else REPORT_TABLES[:2]
    for stem in tables:
        for fmt, ext in TABLE_FORMATS:
            text(f"{stem}.{ext}", format_table(evaluation[stem], fmt, columns(stem, protocol), protocol))
    text("report.json", json.dumps(json_ready(evaluation), indent=1) + "\n")
    for kind in ("precision", "success"):
        paths += plot_curves(evaluation["curves"], kind, report_dir / kind, protocol=protocol)
    for attr, curves in evaluation["attribute_curves"].items():
        n = evaluation["attributes"][attr]
        title = f"Success plots of OPE - {ATTRIBUTE_NAMES.get(attr, attr)} ({n})"
        paths += plot_curves(curves, "success", report_dir / f"success_{attr}", title=title, protocol=protocol)
    return paths


def write_report(out_dir, sequences: Seq[Sequence], trackers: Iterable[str] | None = None,
                 report_dir=None, include_first: bool = True, weighting: str | None = None,
                 protocol: str | Protocol | None = None) -> list[Path]:
    """Score every tracker in ``out_dir`` under ``protocol`` (by default the benchmark's,
    :func:`evaluate`) and write tables and plots to ``report_dir``.

    ``report_dir`` defaults to ``out_dir/report``. Writes ``overall``, ``per_sequence``
    and (when sequences have attributes) ``per_attribute`` tables as ``.txt``, ``.md`` and
    ``.csv``; ``report.json`` with all rows and curves; ``precision`` and ``success`` plots
    and one ``success_<ATTR>`` plot per attribute, each as PNG and SVG. Every file names
    the protocol. Returns the paths.
    """
    return score_and_write(out_dir, sequences, trackers, report_dir, include_first, weighting, protocol)[1]


def score_and_write(out_dir, sequences: Seq[Sequence], trackers: Iterable[str] | None = None, report_dir=None,
                    include_first: bool = True, weighting: str | None = None,
                    protocol: str | Protocol | None = None) -> tuple[dict, list[Path]]:
    """:func:`write_report` that also returns what :func:`evaluate` returned: (evaluation, paths)."""
    report_dir = default_report_dir(out_dir, report_dir)
    _, _, evaluation = score_folders(out_dir, sequences, trackers, report_dir, include_first, weighting, protocol)
    return evaluation, write_files(evaluation, report_dir)


def default_report_dir(out_dir, report_dir=None) -> Path:
    """``report_dir``, by default ``out_dir/report``."""
    return Path(report_dir) if report_dir is not None else Path(out_dir) / "report"


def score_folders(out_dir, sequences: Seq[Sequence], trackers: Iterable[str] | None, report_dir: Path,
                  include_first: bool = True, weighting: str | None = None,
                  protocol: str | Protocol | None = None) -> tuple[dict[str, Path], dict[str, dict], dict]:
    """(tracker folders, their results, :func:`evaluate` of them) for a report into
    ``report_dir``, which is checked to take the report's files before the scoring. A test
    split (ground truth withheld after frame 1) stops here, before any folder is made."""
    sequences = scored_sequences(sequences)
    if _holds_results(report_dir, {s.name for s in sequences}):
        raise DatasetError(f"{report_dir} holds a tracker's results; write the report elsewhere with --report-dir")
    folders = tracker_folders(out_dir, sequences, trackers, exclude=[report_dir])
    results = {name: read_folder(folder, sequences) for name, folder in folders.items()}
    if not results:
        raise DatasetError(f"no tracker results found under {clip(str(out_dir))}")
    ensure_writable(report_dir, report_file_names(sequences), "the report")  # before the scoring
    return folders, results, evaluate(results, sequences, include_first, weighting, protocol)
