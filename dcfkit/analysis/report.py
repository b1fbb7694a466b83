"""Scores, tables and OTB-style plots from result files.

:func:`evaluate` turns results into plain dicts: one row per tracker (``overall``), per
tracker and sequence (``per_sequence``) and per tracker and attribute
(``per_attribute``), plus the averaged curves for plotting. Scores follow a named scoring
protocol of :mod:`dcfkit.protocols` (default ``otb``, the OTB / UAV123 MATLAB toolkit),
and every output names it, with the experiment and any ``--max-frames`` cut
(:mod:`dcfkit.analysis.setting`): first lines of the text and Markdown tables and of
``statistics.txt``, last columns of the CSV tables, ``report.json``, the plot titles and the
LaTeX captions (``overall.tex``: :func:`dcfkit.analysis.latex.comparison_table`). Averages
weigh sequences as the protocol does unless ``weighting`` says otherwise. A tracker's
``fps`` is the mean over sequences of the per-sequence fps (frames / tracker time in that
sequence), not total frames / total time, of runs timed alone only (``fps_measured``,
:mod:`dcfkit.store.timing`; a note under the text and Markdown tables says whose fps is left
out and why). A sequence missing from a tracker's results is
scored as a total failure and counted in the ``missing`` column. :mod:`dcfkit.analysis.report_html`
adds one self-contained HTML page of it all (``dcfkit report --html``). Beside the OTB scores, a
one-pass report has VOT-LT's tracking precision, recall and F of the trackers with confidence
files (``longterm.*``, ``report.json``'s ``long_term``: :mod:`dcfkit.analysis.longterm_report`).
"""
from __future__ import annotations

import dataclasses
import json
import math
import os
from pathlib import Path
from typing import Iterable
from typing import Sequence as Seq

import numpy as np

from dcfkit.analysis.longterm_report import LONG_TERM_FILES, long_term_files, score_long_term
from dcfkit.analysis.plots import plot_curves
from dcfkit.analysis.scoring import Evaluation, evaluate
from dcfkit.analysis.result_fit import check_results_fit, other_folders
from dcfkit.analysis.setting import cut_length, experiment_line
from dcfkit.analysis.stats.results import Comparison, Interval
from dcfkit.analysis.tables import STATISTICS_FILES, columns, format_table, statistics_files
from dcfkit.datasets import ATTRIBUTE_NAMES, DatasetError, Sequence, scored_sequences
from dcfkit.errors import clip, shown
from dcfkit.experiments import Experiment, get_experiment, runs_by_sequence
from dcfkit.protocols import Protocol
from dcfkit.store.files import atomic_write, ensure_writable
from dcfkit.store.results import import_results, load_results

__all__ = ["default_report_dir", "gather_results", "json_ready", "named_folder", "read_folder", "refuse_reset_runs",
           "report_file_names", "score_and_write", "score_folders", "tracker_folders", "write_files", "write_report"]


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
    """Sequence name -> result of the tracker in ``folder`` (see :func:`gather_results`); a
    :class:`DatasetError` if it holds reset-based runs (:func:`refuse_reset_runs`)."""
    names = {s.name for s in sequences}
    if any((folder / f"{n}.json").is_file() for n in names):
        results = load_results(folder.parent, folder.name, sequences)
        refuse_reset_runs(folder, [name for name, result in results.items() if result.resets is not None])
        return results
    return {k: v for k, v in import_results(folder).items() if k in names}


def refuse_reset_runs(folder: Path, names: Seq[str]) -> None:
    """A :class:`DatasetError` if ``names`` (results in ``folder`` whose sidecar records resets)
    is not empty: a reset-based run was restarted from the ground truth after each failure, and
    scored as one pass it would look far better than it is."""
    if names:
        more = f" and {len(names) - 1:,} more" if len(names) > 1 else ""
        raise DatasetError(f"{clip(str(folder))} holds reset-based runs, not one-pass results (the sidecars of "
                           f"{shown(names[0])}{more} record resets); score them with dcfkit report --experiment reset")


def tracker_folders(out_dir, sequences: Seq[Sequence], trackers: Iterable[str] | None = None,
                    exclude: Iterable[Path] = (), sub: str = "") -> dict[str, Path]:
    """Tracker name -> results folder, for a report on ``sequences``.

    A tracker is a sub-folder name of ``out_dir``, a path to a folder of result files, or
    ``NAME=PATH`` to name such a folder (published results beside one's own).
    ``None`` takes every sub-folder of ``out_dir`` holding a ``<sequence>.txt`` of one of
    ``sequences``, except the folders in ``exclude`` that hold no tracker results (a
    report's own folder). A tracker is named by its folder's name, or by ``parent/name``
    where two folders share a name (``reference_results/BACF/UAV123_10fps`` and
    ``.../DR2Track/UAV123_10fps``). ``sub``: an experiment's sub-folder of each tracker's
    folder (:mod:`dcfkit.experiments`), which then holds the results of ``sequences`` (its
    runs); a folder given that has no such sub-folder is taken as it is.
    """
    out_dir = Path(out_dir)
    exclude = {Path(p).resolve() for p in exclude}
    names = {s.name for s in sequences}
    if trackers is None:
        if not out_dir.is_dir():
            raise DatasetError(f"results folder not found: {clip(str(out_dir))}")
        trackers = [p.name for p in sorted(out_dir.iterdir())
                    if p.is_dir() and not p.name.startswith(".") and any((p / sub / f"{n}.txt").is_file() for n in names)
                    and (p.resolve() not in exclude or _holds_results(p, names))]
    folders: dict[Path, tuple[str | None, Path]] = {}
    for tracker in trackers:
        name, folder = named_folder(out_dir, tracker)
        if folder.resolve() in folders and folders[folder.resolve()][0] != name:
            raise DatasetError(f"{clip(str(folder))} is named twice: as {folders[folder.resolve()][0] or folder.name} "
                               f"and as {name or folder.name}")
        folders.setdefault(folder.resolve(), (name, folder))
    given = [n for n, _ in folders.values() if n is not None]
    if len(set(given)) < len(given):
        raise DatasetError(f"two folders are given one name: {', '.join(sorted(n for n in given if given.count(n) > 1))}")
    shared = {name for name in (f.name for _, f in folders.values())
              if sum(g.name == name for _, g in folders.values()) > 1}
    return {name or (f"{folder.resolve().parent.name}/{folder.name}" if folder.name in shared else folder.name):
            folder / sub if sub and (folder / sub).is_dir() else folder for name, folder in folders.values()}


def named_folder(out_dir: Path, tracker: str) -> tuple[str | None, Path]:
    """(the name given, the folder) of a tracker: a sub-folder name of ``out_dir``, a path, or
    ``NAME=PATH`` (a published result folder under a name of its own). A folder whose name
    holds '=' is taken as a folder."""
    # os.path.isdir: a name too long for the file system is no folder (Path.is_dir raises)
    for candidate in (out_dir / tracker, Path(tracker)):
        if os.path.isdir(candidate):
            return None, candidate
    name, sep, path = tracker.partition("=")
    if sep and name.strip() and path and name.isprintable():
        folder = out_dir / path if os.path.isdir(out_dir / path) else Path(path)
        if os.path.isdir(folder):
            return name.strip(), folder
        raise DatasetError(f"no results for tracker {shown(name)}: {clip(path)} is not a folder")
    raise DatasetError(f"no results for tracker {shown(tracker)}: neither {clip(str(out_dir / tracker))} "
                       f"nor {clip(tracker)} is a folder")


def _holds_results(folder: Path, names: set[str]) -> bool:
    """Whether ``folder`` has a result file or sidecar of a sequence (a report folder has none)."""
    return any((folder / f"{n}.txt").is_file() or (folder / f"{n}.json").is_file() for n in names)


def json_ready(obj):
    """``obj`` with arrays as lists, typed statistics as their records
    (:mod:`dcfkit.analysis.stats.results`) and non-finite floats as None, for ``json.dumps``."""
    if isinstance(obj, (Interval, Comparison)):
        return json_ready(obj.as_record())
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
TABLE_FORMATS = (("table", "txt"), ("markdown", "md"), ("csv", "csv"), ("latex", "tex"))
NOTED = ("table", "markdown")  # the formats a note may follow (:func:`dcfkit.store.timing.fps_note`)


def report_file_names(sequences: Seq[Sequence]) -> list[str]:
    """Every file a report on ``sequences`` may write."""
    attributes = sorted({a for s in sequences for a, present in s.attributes.items() if present})
    plots = ["precision", "success"] + [f"{kind}_{a}" for a in attributes for kind in ("precision", "success")]
    return ([f"{t}.{ext}" for t in REPORT_TABLES for _, ext in TABLE_FORMATS] + [*STATISTICS_FILES, "report.json",
                                                                                   "report.html"]
            + list(LONG_TERM_FILES)
            + [f"{p}.{ext}" for p in plots for ext in ("png", "svg")])


def write_files(evaluation: Evaluation, report_dir: Path) -> list[Path]:
    """The tables, ``statistics.txt``, ``report.json``, the long-term tables and curves
    (:func:`~dcfkit.analysis.longterm_report.long_term_files`) and plots of :func:`write_report` from
    ``evaluation``, each naming the experiment, the protocol and any ``--max-frames`` cut."""
    paths = []
    protocol = evaluation.protocol.name
    experiment, cut = evaluation.settings.get("experiment", "ope"), evaluation.settings.get("max_frames")

    def text(name, content):
        path = report_dir / name
        atomic_write(path, content)
        paths.append(path)

    tables = REPORT_TABLES if evaluation.per_attribute else REPORT_TABLES[:2]
    note = evaluation.settings.get("fps_note")  # whose fps is left out, and why
    for stem in tables:
        for fmt, ext in TABLE_FORMATS:
            table = format_table(getattr(evaluation, stem), fmt, columns(stem, protocol), protocol,
                                 evaluation.statistics if stem == "overall" else None,
                                 experiment=experiment, max_frames=cut,
                                 datasets=evaluation.settings["datasets"])
            noted = note and fmt in NOTED and stem != "per_attribute"
            text(f"{stem}.{ext}", table + (f"\n{note}\n" if noted else ""))
    head = [experiment_line(experiment, cut), evaluation.protocol.describe(), ""]
    setting = {"protocol": protocol, "experiment": get_experiment(experiment).name,
               **({} if cut is None else {"max_frames": cut})}  # the CSV tables' last columns
    for name, content in statistics_files(evaluation.statistics, head, setting).items():
        text(name, content)
    text("report.json", json.dumps(json_ready(evaluation.as_record()), indent=1) + "\n")
    if evaluation.long_term:
        long_term_files(evaluation.long_term, experiment, cut, text)
    run = experiment.upper() + (f", first {cut} frames" if cut is not None else "")
    for kind in ("precision", "success"):
        paths += plot_curves(evaluation.curves, kind, report_dir / kind, title=f"{kind.capitalize()} plots of {run}",
                             protocol=protocol)
    for attr, curves in evaluation.attribute_curves.items():
        name = f"{ATTRIBUTE_NAMES.get(attr, attr)} ({evaluation.attributes[attr]})"
        for kind in ("precision", "success"):
            title = f"{kind.capitalize()} plots of {run} - {name}"
            paths += plot_curves(curves, kind, report_dir / f"{kind}_{attr}", title=title, protocol=protocol)
    return paths


def write_report(out_dir, sequences: Seq[Sequence], trackers: Iterable[str] | None = None,
                 report_dir=None, include_first: bool = True, weighting: str | None = None,
                 protocol: str | Protocol | None = None, *, missing: str = "skip",
                 experiment: str | Experiment = "ope") -> list[Path]:
    """Score every tracker in ``out_dir`` under ``protocol`` (by default the benchmark's,
    :func:`evaluate`) and write tables and plots to ``report_dir``.

    ``report_dir`` defaults to :func:`default_report_dir`. Writes ``overall``, ``per_sequence``
    and (when sequences have attributes) ``per_attribute`` tables as ``.txt``, ``.md``, ``.csv``
    and ``.tex``; ``statistics.txt``; ``report.json`` with all rows and curves; for one pass, the long-term
    ``longterm.txt``, ``.md``, ``.csv`` and ``longterm_curves.csv``; ``precision`` and ``success`` plots
    and ``precision_<ATTR>`` and ``success_<ATTR>`` plots per attribute, each as PNG and SVG. Every file names
    the experiment, the protocol and any ``--max-frames`` cut. ``missing`` is :func:`evaluate`'s: by default the sequences every tracker
    has a result for are scored, the others named. ``experiment`` ``tre`` or ``sre`` scores
    each tracker's runs of it (``<tracker>/<experiment>/``), pooled per sequence. Returns the paths.
    """
    return score_and_write(out_dir, sequences, trackers, report_dir, include_first, weighting, protocol,
                           missing=missing, experiment=experiment)[1]


def score_and_write(out_dir, sequences: Seq[Sequence], trackers: Iterable[str] | None = None, report_dir=None,
                    include_first: bool = True, weighting: str | None = None,
                    protocol: str | Protocol | None = None, *, missing: str = "skip",
                    experiment: str | Experiment = "ope", baseline: str | None = None) -> tuple[dict, list[Path]]:
    """:func:`write_report` that also returns what :func:`evaluate` returned: (evaluation, paths)."""
    report_dir = default_report_dir(out_dir, report_dir, experiment)
    _, _, evaluation = score_folders(out_dir, sequences, trackers, report_dir, include_first, weighting, protocol,
                                     missing=missing, experiment=experiment, baseline=baseline)
    return evaluation, write_files(evaluation, report_dir)


def default_report_dir(out_dir, report_dir=None, experiment: str | Experiment = "ope") -> Path:
    """``report_dir``, by default ``<out_dir>_report`` beside ``out_dir`` (and its
    ``<experiment>/`` but for one pass): not in ``out_dir``, whose every folder pysot's
    ``eval.py`` takes for a tracker."""
    if report_dir is not None:
        return Path(report_dir)
    out = Path(out_dir).resolve()
    sub = get_experiment(experiment).folder
    folder = out.with_name(f"{out.name}_report")
    return folder / sub if sub else folder


def score_folders(out_dir, sequences: Seq[Sequence], trackers: Iterable[str] | None, report_dir: Path,
                  include_first: bool = True, weighting: str | None = None, protocol: str | Protocol | None = None,
                  *, missing: str = "skip", experiment: str | Experiment = "ope", baseline: str | None = None
                  ) -> tuple[dict[str, Path], dict[str, dict], dict]:
    """(tracker folders, their results, :func:`evaluate` of them) for a report into
    ``report_dir``, which is checked to take the report's files before the scoring. A test
    split (ground truth withheld after frame 1) stops here, before any folder is made."""
    sequences = scored_sequences(sequences)
    if _holds_results(report_dir, {s.name for s in sequences}):
        raise DatasetError(f"{report_dir} holds a tracker's results; write the report elsewhere with --report-dir")
    experiment = get_experiment(experiment)
    if experiment.scoring != "otb":
        raise DatasetError(f"{experiment.name} results are scored by their own scoring ({experiment.scoring}): "
                           f"dcfkit report --experiment {experiment.name}")
    by_sequence = runs_by_sequence(sequences, experiment)
    runs = [run for found in by_sequence.values() for run in found]
    folders = tracker_folders(out_dir, runs, trackers, exclude=[report_dir], sub=experiment.folder)
    if not folders and trackers is None:  # sub-folders of results, none of these sequences': whose?
        folders = other_folders(out_dir, experiment.folder)
    check_results_fit(out_dir, folders, runs, missing, cut_length(sequences))
    results = {name: read_folder(folder, runs) for name, folder in folders.items()}
    if not results:
        raise DatasetError(f"no tracker results{' of experiment ' + experiment.name if experiment.folder else ''} "
                           f"found under {clip(str(out_dir))}")
    ensure_writable(report_dir, report_file_names(sequences), "the report")  # before the scoring
    evaluation = evaluate(results, sequences, include_first, weighting, protocol, missing, experiment, by_sequence,
                          baseline)
    scored = [s for s in sequences if s.name not in evaluation.settings["left_out"]]
    long_term = score_long_term(folders, results, scored, experiment)
    return folders, results, dataclasses.replace(evaluation, long_term=long_term)
