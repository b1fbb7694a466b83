"""``dcfkit report --experiment reset``: the reset-based runs of every tracker scored
(:mod:`dcfkit.analysis.reset_scores`) and written as tables, statistics and JSON."""
from __future__ import annotations

import json
import logging
from pathlib import Path
from typing import Iterable
from typing import Sequence as Seq

from dcfkit.analysis.report import TABLE_FORMATS, default_report_dir, json_ready, tracker_folders
from dcfkit.analysis.reset_scores import ResetRun, score_resets
from dcfkit.analysis.tables import format_rows, statistics_lines
from dcfkit.datasets import DatasetError, Sequence, scored_sequences
from dcfkit.errors import clip
from dcfkit.experiments import EXPERIMENTS
from dcfkit.running.files import atomic_write, ensure_writable
from dcfkit.running.results import ResultStore

log = logging.getLogger(__name__)

RESET_COLUMNS = {"overall": ("tracker", "eao", "eao_ci_low", "eao_ci_high", "accuracy", "failures", "sequences"),
                 "per_sequence": ("tracker", "sequence", "accuracy", "failures", "frames")}
EXPERIMENT = EXPERIMENTS["reset"]


def reset_runs(folder: Path, sequences: Seq[Sequence]) -> dict[str, ResetRun]:
    """Sequence name -> :class:`ResetRun` of the intact reset-based results in ``folder``."""
    runs, by_name = {}, {s.name: s for s in sequences}
    for name, result in ResultStore(folder).load(sequences).items():
        seq = by_name[name]
        if result.resets is None:
            log.warning("%s: the result of %r is not a reset-based run (no 'resets' in its sidecar): left out",
                        folder, name)
            continue
        height, width = seq.frame(0).shape[:2]
        runs[name] = ResetRun(result.boxes, seq.ground_truth, tuple(i - 1 for i in result.resets["starts"]),
                              tuple(i - 1 for i in result.resets["failures"]), (width, height))
    return runs


def write_reset_report(out_dir, sequences: Seq[Sequence], trackers: Iterable[str] | None = None,
                       report_dir=None, interval: tuple[int, int] | None = None) -> tuple[dict, list[Path]]:
    """Score the reset-based runs (``<tracker>/reset/``) of every tracker in ``out_dir`` on the
    sequences all of them ran, and write ``reset_overall`` and ``reset_per_sequence`` tables
    (``.txt``, ``.md``, ``.csv``), ``statistics.txt`` and ``reset.json`` to ``report_dir``
    (default ``<out_dir>_report/reset``). Returns (the scores, the paths)."""
    sequences = scored_sequences(sequences)
    report_dir = default_report_dir(out_dir, report_dir, EXPERIMENT)
    folders = tracker_folders(out_dir, sequences, trackers, exclude=[report_dir], sub=EXPERIMENT.folder)
    results = {name: reset_runs(folder, sequences) for name, folder in folders.items()}
    if not results:
        raise DatasetError(f"no reset-based results found under {clip(str(out_dir))} (dcfkit eval --experiment reset)")
    names = [f"reset_{t}.{ext}" for t in RESET_COLUMNS for _, ext in TABLE_FORMATS if ext != "tex"]
    ensure_writable(report_dir, names + ["statistics.txt", "reset.json"], "the report")
    scores = score_resets(results, {s.name: len(s) for s in sequences}, interval)
    scores["experiment"] = {"name": EXPERIMENT.name, "title": EXPERIMENT.title, "source": EXPERIMENT.source}
    paths = []
    for table, columns in RESET_COLUMNS.items():
        for fmt, ext in TABLE_FORMATS:
            if ext != "tex":
                paths.append(_write(report_dir / f"reset_{table}.{ext}", format_rows(scores[table], fmt, columns)))
    paths.append(_write(report_dir / "statistics.txt", "\n".join(statistics_lines(scores["statistics"])) + "\n"))
    paths.append(_write(report_dir / "reset.json", json.dumps(json_ready(scores), indent=1) + "\n"))
    return scores, paths


def _write(path: Path, text: str) -> Path:
    atomic_write(path, text)
    return path
