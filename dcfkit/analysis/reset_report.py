"""``dcfkit report --experiment reset``: the reset-based runs of every tracker scored
(:mod:`dcfkit.analysis.reset_scores`) and written as tables, statistics and JSON."""
from __future__ import annotations

import itertools
import json
import logging
from pathlib import Path
from typing import Iterable
from typing import Sequence as Seq

import numpy as np

from dcfkit.analysis.latex import comparison_table, interval_cell
from dcfkit.analysis.report import TABLE_FORMATS, default_report_dir, json_ready, tracker_folders
from dcfkit.analysis.result_fit import check_results_fit, other_folders
from dcfkit.analysis.reset_scores import ResetRun, score_resets
from dcfkit.analysis.setting import cut_length, experiment_line, experiment_record
from dcfkit.analysis.stats.results import Interval
from dcfkit.analysis.tables import STATISTICS_FILES, format_rows, statistics_files
from dcfkit.datasets import DatasetError, Sequence, scored_sequences
from dcfkit.errors import ConfigError, clip
from dcfkit.experiments import EXPERIMENTS
from dcfkit.experiments.vot import RULES, SKIP, get_rule, next_start
from dcfkit.store.files import atomic_write, ensure_writable
from dcfkit.store.results import ResultStore

log = logging.getLogger(__name__)

RESET_COLUMNS = {"overall": ("tracker", "eao", "eao_ci_low", "eao_ci_high", "accuracy", "failures", "sequences"),
                 "per_sequence": ("tracker", "sequence", "accuracy", "failures", "frames")}
EXPERIMENT = EXPERIMENTS["reset"]


def reset_runs(folder: Path, sequences: Seq[Sequence]) -> dict[str, ResetRun]:
    """Sequence name -> :class:`ResetRun` of the intact reset-based results in ``folder``, each
    with the rule that made it; a run of no known rule (dcfkit <= 0.9.0's continuous overlap), or
    whose starts and failures are not those its boxes and ground truth give (:func:`resets_problem`),
    is left out, and said so."""
    runs, by_name = {}, {s.name: s for s in sequences}
    for name, result in ResultStore(folder).load(sequences).items():
        seq = by_name[name]
        if result.resets is None:
            log.warning("%s: the result of %r is not a reset-based run (no 'resets' in its sidecar): left out",
                        folder, name)
            continue
        rule = result.resets.get("rule")
        if not isinstance(rule, str) or rule not in RULES:
            log.warning("%s: sequence %r left out, its failures were decided by %s, not a toolkit's rule (%s); run "
                        "dcfkit eval --experiment reset again to recompute it", folder, name,
                        "dcfkit <= 0.9.0's continuous overlap" if rule is None else f"rule {rule!r}",
                        ", ".join(RULES))
            continue
        run = ResetRun(result.boxes, seq.ground_truth, tuple(i - 1 for i in result.resets["starts"]),
                       tuple(i - 1 for i in result.resets["failures"]), seq.image_size, rule)
        problem = resets_problem(run)
        if problem is not None:
            log.warning("%s: sequence %r left out, its sidecar's resets are not its boxes' (%s); run it again to "
                        "recompute it", folder, name, problem)
            continue
        runs[name] = run
    return runs


ROUNDING = 1e-3  # the most a result file's %.3f moves a box's edge (x and w each by 0.0005), and a margin


def resets_problem(run: ResetRun) -> str | None:
    """Where (``frame <n>``, 1-based) the ``starts`` and ``failures`` of ``run`` part from those its
    rule (:class:`~dcfkit.experiments.vot.ResetRule`) gives from its boxes and ground truth, or
    None. The loop is the runs' own (:mod:`dcfkit.experiments.reset`): a failure is the first frame
    after a start whose box does not overlap the ground truth; the next start is
    :func:`~dcfkit.experiments.vot.next_start` from :data:`~dcfkit.experiments.vot.SKIP` frames
    later (dcfkit <= 0.9.0 did not move a start past a box off the image: that start is taken
    too). A decision the rounding of the boxes could turn is taken either way; frames no tracker
    ran must have no box."""
    gt, size = run.gt, None if run.bounds is None else (run.bounds[1], run.bounds[0])
    tracked = np.zeros(len(gt), dtype=bool)
    due = 0
    for k in itertools.count():
        expected = {next_start(gt, due), next_start(gt, due, size)}  # None: no start is due
        start = run.starts[k] if k < len(run.starts) else None
        if start not in expected:
            return (f"frame {start + 1}: its sidecar records a start where the rule gives none" if start is not None
                    else f"frame {min(expected - {None}) + 1}: the rule starts the tracker again, its sidecar "
                         f"records no start")
        if start is None:
            unused = [("failure", i) for i in run.failures[k:]]
            break
        failure = run.failures[k] if k < len(run.failures) else None
        problem = _segment_problem(run, start, failure)
        if problem is not None:
            return problem
        tracked[start:len(gt) if failure is None else failure + 1] = True
        if failure is None:
            unused = [("start", i) for i in run.starts[k + 1:]]
            break
        due = failure + SKIP
    if unused:
        what, frame = unused[0]
        return f"frame {frame + 1}: its sidecar records a {what} the rule does not give"
    stray = np.flatnonzero(~tracked & np.isfinite(run.boxes).any(axis=1))
    return f"frame {stray[0] + 1}: a box where no tracker ran" if stray.size else None


def _segment_problem(run: ResetRun, start: int, failure: int | None) -> str | None:
    """Why the tracking from ``start`` is not one that fails on ``failure`` (None: never), or None."""
    if failure is not None and failure <= start:
        return f"frame {failure + 1}: its sidecar records a failure before its start on frame {start + 1}"
    end = len(run.gt) if failure is None else failure
    for i in range(start + 1, end):
        if _fails(run, i, ROUNDING):
            return f"frame {i + 1}: the box does not overlap the ground truth, a failure its sidecar does not record"
    if failure is not None and not _fails(run, failure, -ROUNDING):
        return f"frame {failure + 1}: its sidecar records a failure where the box overlaps the ground truth"
    return None


def _fails(run: ResetRun, i: int, margin: float) -> bool:
    """Whether frame ``i``'s box, ``margin`` wider on each side, fails (does not overlap the ground
    truth by the run's rule: :meth:`~dcfkit.experiments.vot.ResetRule.failed`)."""
    x, y, w, h = run.boxes[i]
    return get_rule(run.rule).failed((x - margin, y - margin, w + 2 * margin, h + 2 * margin), run.gt[i], run.bounds)


def write_reset_report(out_dir, sequences: Seq[Sequence], trackers: Iterable[str] | None = None,
                       report_dir=None, interval: tuple[int, int] | None = None, protocol: str | None = None,
                       baseline: str | None = None) -> tuple[dict, list[Path]]:
    """Score the reset-based runs (``<tracker>/reset/``) of every tracker in ``out_dir`` on the
    sequences all of them ran (differences from ``baseline``, by default the best), with the
    rule they were made with (``protocol``, if given, must be it: a :class:`ConfigError` if not,
    or if the runs were made with several), and write
    ``reset_overall`` and ``reset_per_sequence`` tables (``.txt``, ``.md``, ``.csv``;
    ``reset_overall.tex``: :func:`reset_latex`), ``statistics.txt`` and ``reset.json`` to
    ``report_dir`` (default ``<out_dir>_report/reset``), each naming the experiment, the rule
    and any ``--max-frames`` cut. Returns (the scores, the paths)."""
    sequences = scored_sequences(sequences)
    report_dir = default_report_dir(out_dir, report_dir, EXPERIMENT)
    folders = tracker_folders(out_dir, sequences, trackers, exclude=[report_dir], sub=EXPERIMENT.folder)
    found = folders if folders or trackers is not None else other_folders(out_dir, EXPERIMENT.folder)
    check_results_fit(out_dir, found, sequences, "skip", cut_length(sequences))
    results = {name: reset_runs(folder, sequences) for name, folder in folders.items()}
    if not results:
        raise DatasetError(f"no reset-based results found under {clip(str(out_dir))} (dcfkit eval --experiment reset)")
    if not any(all(s.name in runs for runs in results.values()) for s in sequences):
        raise DatasetError(f"none of the {len(sequences)} sequences has a reset-based result that can be scored "
                           f"from every tracker (a warning says why a result was left out); run them with dcfkit "
                           f"eval --experiment reset")
    rule = _one_rule(results, protocol)
    names = [f"reset_{t}.{ext}" for t in RESET_COLUMNS for _, ext in TABLE_FORMATS if ext != "tex"]
    ensure_writable(report_dir, names + ["reset_overall.tex", *STATISTICS_FILES, "reset.json"], "the report")
    scores = score_resets(results, {s.name: len(s) for s in sequences}, interval, baseline)
    scores["experiment"] = experiment_record(EXPERIMENT)
    scores["max_frames"] = cut_length(sequences)
    scores["rule"] = {"name": rule.name, "title": rule.title, "tables": rule.tables}
    paths = []
    for table, columns in RESET_COLUMNS.items():
        for fmt, ext in TABLE_FORMATS:
            if ext != "tex":
                paths.append(_write(report_dir / f"reset_{table}.{ext}", reset_table(scores, table, fmt)))
    paths.append(_write(report_dir / "reset_overall.tex", reset_latex(scores)))
    head = [experiment_line(EXPERIMENT, scores["max_frames"]), _eao_line(scores), ""]
    setting = {"rule": rule.name, "experiment": EXPERIMENT.name,
               **({} if scores["max_frames"] is None else {"max_frames": scores["max_frames"]})}
    for name, content in statistics_files(scores["statistics"], head, setting).items():
        paths.append(_write(report_dir / name, content))
    paths.append(_write(report_dir / "reset.json", json.dumps(json_ready(scores), indent=1) + "\n"))
    return scores, paths


def _eao_line(scores: dict) -> str:
    low, high = scores["interval"]
    rule = scores["rule"]
    return (f"overlaps and failures: {rule['name']} ({rule['title']}); EAO over sequence lengths {low}..{high} "
            f"(VOT2016), its interval a percentile bootstrap over sequences")


def reset_table(scores: dict, table: str, fmt: str) -> str:
    """The ``overall`` or ``per_sequence`` rows of :func:`score_resets` as :func:`format_rows`
    ``fmt``, naming the experiment and any cut: first lines, or last CSV columns."""
    rows, columns, cut = scores[table], RESET_COLUMNS[table], scores.get("max_frames")
    if fmt == "csv":
        extra = {"experiment": EXPERIMENT.name, **({} if cut is None else {"max_frames": cut})}
        return format_rows([{**r, **extra} for r in rows], fmt, (*columns, *extra))
    return f"{experiment_line(EXPERIMENT, cut)}\n{_eao_line(scores)}\n\n" + format_rows(rows, fmt, columns)


def reset_latex(scores: dict) -> str:
    """The overall scores of :func:`score_resets` as a LaTeX comparison table
    (:func:`~dcfkit.analysis.latex.comparison_table`): each tracker's EAO with its interval, then
    its accuracy and failures with their intervals and paired differences from the best."""
    eao = {r["tracker"]: interval_cell(Interval(r["eao"], r["eao_ci_low"], r["eao_ci_high"], r["sequences"]))
           for r in scores["overall"]}
    if not scores["statistics"]:
        raise DatasetError("no tracker's reset-based runs to tabulate")
    return comparison_table(scores["statistics"], [experiment_line(EXPERIMENT, scores.get("max_frames")),
                                                   _eao_line(scores)], lead=[("EAO [CI]", eao)])


def _one_rule(results: dict[str, dict[str, ResetRun]], protocol: str | None):
    """The :class:`~dcfkit.experiments.vot.ResetRule` every run of ``results`` was made with."""
    made = {}
    for tracker, runs in results.items():
        for run in runs.values():
            made.setdefault(run.rule, tracker)
    if len(made) > 1:
        raise ConfigError("the reset-based runs were made with different failure rules (" + "; ".join(
            f"{rule}: {tracker}'s" for rule, tracker in made.items()) + "); their scores do not compare: run them "
            "again with one --protocol, or report them apart with --trackers")
    rule = get_rule(next(iter(made), protocol))
    if protocol is not None and made and protocol != rule.name:
        raise ConfigError(f"--protocol {protocol}: these reset-based runs were made with the {rule.name} rule, "
                          f"whose failures restarted them; leave --protocol out or give {rule.name} (dcfkit eval "
                          f"--experiment reset --protocol {protocol} makes runs of the other rule)")
    return rule


def _write(path: Path, text: str) -> Path:
    atomic_write(path, text)
    return path
