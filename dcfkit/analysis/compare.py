"""Parity check: two folders of result files side by side, sequence by sequence.

:func:`compare_folders` reads ``RESULTS/<sequence>.txt`` and ``REFERENCE/<sequence>.txt``
(1-based ``x,y,w,h`` per line, commas, tabs or spaces: the layout ``dcfkit eval`` writes and
that of published result files) for the sequences present in both folders and in the
given dataset, and returns one row per sequence:

* ``precision``, ``auc`` of the results and ``precision_ref``, ``auc_ref`` of the reference,
  scored against the ground truth under a scoring protocol (:mod:`dcfkit.protocols`), and
  the differences ``d_precision``, ``d_auc`` (results minus reference);
* ``iou``: the mean over frames of the IoU between the two box series (continuous boxes;
  a frame where both files hold the same values counts 1, also when both are NaN; a frame
  where only one box is NaN counts 0);
* ``diverges_at``: the first frame (1-based) where the two centres are more than
  ``divergence_px`` apart (a box NaN in one file only counts as apart), or None.

Under TRE or SRE (``experiment``) the files are each sequence's runs, and a row pools them
(:func:`compare_folders`). The ``mean`` row averages precision and AUC as the protocol averages
sequences, and the per-sequence IoUs with equal weights. Sequences found in only one folder
(all their runs), files in both but of no sequence of the dataset, sequences with some runs
but all of them in neither folder (``incomplete``) and files whose dcfkit sidecar says they
are damaged are listed in ``left_out``.
``platforms`` lists each folder's platforms as their sidecars record them
(:mod:`dcfkit.store.platforms`; "not recorded" for files without one) and ``platform_differences``
what differs between the two files of a sequence, each with its count of sequences unless all have
it (ten lines at most, then a count of the others): boxes from different platforms can part where a
float decision is close (docs/architecture.md). A sequence with a non-finite score (no frame
counted) is named in ``non_finite`` and left out of that score's statistics.
"""
from __future__ import annotations

import logging
import math
from collections import Counter
from pathlib import Path
from typing import Iterable, Mapping

import numpy as np

from dcfkit.analysis import metrics
from dcfkit.analysis.report import refuse_reset_runs
from dcfkit.analysis.statistics import METHOD, Difference, mean_interval, paired_difference
from dcfkit.datasets import DatasetError, Sequence, benchmark_protocol, read_boxes, scored_sequences
from dcfkit.errors import clip, shown
from dcfkit.experiments import Experiment, get_experiment, runs_by_sequence
from dcfkit.protocols import Protocol, get_protocol
from dcfkit.store import platforms
from dcfkit.store.results import ResultStore, result_files

__all__ = ["COLUMNS", "PLATFORM_NOISE", "compare_folders", "counted_lines", "first_divergence", "noise_floor",
           "score_statistics", "series_iou"]

COLUMNS = ("sequence", "frames", "precision", "precision_ref", "d_precision", "auc", "auc_ref", "d_auc",
           "iou", "diverges_at")

log = logging.getLogger(__name__)

#: How far a last-bit change in the arithmetic (FFTW for pocketfft) moved the shipped configs'
#: AUC, measured by benchmarks/platform_noise.py on the eight development sequences: on one
#: sequence and on their mean (docs/results.md, "Platform noise", where the BACF preset's
#: 0.338 and 0.042 are also given). tests/analysis/test_compare.py holds these to that page.
PLATFORM_NOISE = {"auc_sequence": 0.012, "auc_mean_of_8": 0.001, "precision_mean_of_8": 0.003,
                  "source": 'docs/results.md, "Platform noise" (benchmarks/platform_noise.py, dcfkit 0.6.0)'}


def series_iou(a, b) -> np.ndarray:
    """``(N,)`` IoU between two 0-based box series: 1 where the rows are identical (NaN
    included), 0 where only one is non-finite or a box is empty, else the continuous IoU."""
    a, b = metrics.as_boxes(a), metrics.as_boxes(b)
    out = metrics.iou(a, b)
    out[~np.isfinite(b).all(axis=1)] = 0.0
    out[_identical(a, b)] = 1.0
    return out


def first_divergence(a, b, px: float) -> int | None:
    """First frame (1-based) where the centres of ``a`` and ``b`` are more than ``px``
    apart (identical rows never are; a NaN in one of them always is), or None."""
    a, b = metrics.as_boxes(a), metrics.as_boxes(b)
    d = (a[:, :2] + a[:, 2:] / 2) - (b[:, :2] + b[:, 2:] / 2)
    with np.errstate(invalid="ignore"):
        apart = ~(np.hypot(d[:, 0], d[:, 1]) <= px) & ~_identical(a, b)
    return int(np.argmax(apart)) + 1 if apart.any() else None


def _identical(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return ((a == b) | (np.isnan(a) & np.isnan(b))).all(axis=1)


def compare_folders(results, reference, sequences: Iterable[Sequence], protocol: str | Protocol | None = None,
                    divergence_px: float = 2.0, experiment: str | Experiment = "ope") -> dict:
    """Compare the result files of two folders on ``sequences`` (their ground truth).

    ``experiment`` ``tre`` or ``sre``: the files are the runs of each sequence (``<run>.txt``,
    :mod:`dcfkit.experiments`); a sequence is compared when both folders hold all its runs.
    Its scores pool its runs' frames (:func:`metrics.pool_runs`, as ``dcfkit report``), its
    ``iou`` is the mean over all their frames, and ``diverges_at`` is ``"k:f"``, frame ``f``
    of run ``k``, the first run that diverges.

    Returns a plain dict: ``protocol`` (name), ``divergence_px``, ``results`` and
    ``reference`` (the folders), ``rows`` (one per compared sequence, keys
    :data:`COLUMNS`), ``mean`` (the same keys, ``sequence`` "mean", ``frames`` the total,
    ``diverges_at`` None), ``diverged`` (how many sequences diverge), ``left_out``
    (``only_in_results``, ``only_in_reference``, ``not_in_dataset``, ``damaged``: sequence names)
    and the statistics of :func:`score_statistics`: ``statistics``, ``auc_difference``,
    ``wilcoxon_p`` (AUC's), ``precision_difference`` and ``precision_wilcoxon_p``.
    Raises :class:`DatasetError` for a missing folder, a folder of reset-based runs, a malformed
    line (naming file and line), two files of one sequence with different line counts, or a line
    count that is not the sequence's frame count (naming the sequence). Sequences whose ground truth is
    withheld after frame 1 (test splits) are left out, as in :func:`dcfkit.analysis.scoring.evaluate`,
    whose default ``protocol`` (the benchmark's) is this one's too.
    """
    sequences = list(sequences)
    proto = get_protocol(protocol or benchmark_protocol(sequences))
    exp = get_experiment(experiment)
    if exp.scoring != "otb":
        raise DatasetError(f"compare sets box series side by side; {exp.name} runs are scored by dcfkit report "
                           f"--experiment {exp.name}")
    if not divergence_px >= 0:
        raise DatasetError(f"divergence_px must be a number >= 0, got {shown(divergence_px)}")
    sequences = scored_sequences(sequences)
    runs = runs_by_sequence(sequences, exp) if exp.pooled else {seq.name: [seq] for seq in sequences}
    by_name = {run.name: run for found in runs.values() for run in found}
    (ours, damaged, our_platforms), (theirs, damaged_ref, their_platforms) = (_intact_files(results, by_name),
                                                                              _intact_files(reference, by_name))
    complete = [{s.name for s in sequences if runs[s.name] and all(r.name in files for r in runs[s.name])}
                for files in (ours, theirs)]
    both = [s for s in sequences if s.name in complete[0] & complete[1]]
    stray = set(ours) - set(by_name), set(theirs) - set(by_name)  # files of no run of a dataset sequence
    left_out = {"only_in_results": sorted((complete[0] - complete[1]) | (stray[0] - stray[1])),
                "only_in_reference": sorted((complete[1] - complete[0]) | (stray[1] - stray[0])),
                "not_in_dataset": sorted((set(ours) & set(theirs)) - set(by_name)),
                "incomplete": sorted({s.name for s in sequences if any(r.name in ours or r.name in theirs
                                                                       for r in runs[s.name])}
                                     - complete[0] - complete[1]),  # some runs, but all in neither folder
                "damaged": sorted(set(damaged) | set(damaged_ref))}
    if not both:
        raise DatasetError(f"no sequence has {_what(exp)} in both {clip(str(results))} ({len(ours)} files) and "
                           f"{clip(str(reference))} ({len(theirs)} files) and ground truth in the dataset "
                           f"({len(sequences)} sequences)")
    rows, scores, scores_ref = [], [], []
    for seq in both:
        row, s, s_ref = _compared(seq, runs[seq.name], ours, theirs, proto, divergence_px, exp.pooled)
        rows.append(row)
        scores.append(s)
        scores_ref.append(s_ref)
    files = [run.name for s in both for run in runs[s.name]]  # each compared file, a run's under TRE or SRE
    unit = "runs" if exp.pooled else "sequences"
    mean = _row("mean", sum(r["frames"] for r in rows), metrics.average(scores, protocol=proto),
                metrics.average(scores_ref, protocol=proto), float(np.mean([r["iou"] for r in rows])), None)
    return {"protocol": proto.name, "experiment": exp.name, "divergence_px": float(divergence_px),
            "results": str(results), "reference": str(reference), "rows": rows, "mean": mean, **score_statistics(rows),
            "noise_floor": noise_floor(rows),
            "diverged": sum(r["diverges_at"] is not None for r in rows), "left_out": left_out,
            "platforms": {side: counted_lines(Counter(platforms.describe(records[f]) for f in files), len(files), unit)
                          for side, records in (("results", our_platforms), ("reference", their_platforms))},
            "platform_differences": counted_lines(Counter(d for f in files for d in set(
                platforms.differences(our_platforms[f], their_platforms[f]))), len(files), unit)}


def score_statistics(rows: list[dict]) -> dict:
    """Per score (AUC, precision): each folder's mean with its interval (``results``,
    ``reference``: :class:`~dcfkit.analysis.stats.results.Interval`), the paired ``difference``
    results - reference (:mod:`dcfkit.analysis.statistics`) and ``non_finite``, the sequences
    left out of them for a non-finite score in either folder; the AUC's and the precision's
    difference and Wilcoxon p also at the top level, for scripts."""
    found = {}
    for score in ("auc", "precision"):
        ours, theirs = [r[score] for r in rows], [r[f"{score}_ref"] for r in rows]
        found[score] = {"results": mean_interval(ours), "reference": mean_interval(theirs),
                        "difference": paired_difference(ours, theirs), "non_finite": _non_finite(rows, f"d_{score}")}
    auc, precision = found["auc"]["difference"], found["precision"]["difference"]
    return {"statistics": {"method": METHOD, **found},
            "auc_difference": _interval_only(auc), "wilcoxon_p": auc.wilcoxon_p,
            "precision_difference": _interval_only(precision), "precision_wilcoxon_p": precision.wilcoxon_p}


def _interval_only(difference: Difference) -> dict:
    """The mean and interval of a difference's record (the top-level keys scripts read)."""
    return {k: v for k, v in difference.as_record().items() if k in ("mean", "ci_low", "ci_high")}


def noise_floor(rows: list[dict]) -> dict:
    """The measured :data:`PLATFORM_NOISE` beside ``rows``' AUC differences: ``exceeds`` when
    the mean difference is beyond the most the platform moved a single sequence (which bounds
    what it can do to any mean; None, no verdict, when no difference is finite), and the
    sequences whose difference is beyond that. The mean is over the finite differences; the
    sequences left out are ``non_finite``."""
    floor = PLATFORM_NOISE["auc_sequence"]
    finite = [r["d_auc"] for r in rows if math.isfinite(r["d_auc"])]
    mean = float(np.mean(finite)) if finite else math.nan
    beyond = [r["sequence"] for r in rows if abs(r["d_auc"]) > floor]
    return {**PLATFORM_NOISE, "mean_auc_difference": mean, "exceeds": bool(abs(mean) > floor) if finite else None,
            "sequences_beyond": beyond, "non_finite": _non_finite(rows, "d_auc")}


def _non_finite(rows: list[dict], key: str) -> list[str]:
    """The sequences of ``rows`` whose ``key`` (a difference: non-finite if either score is) is not finite."""
    return [r["sequence"] for r in rows if not math.isfinite(r[key])]


def counted_lines(counts: Mapping[str, int], total: int, unit: str = "sequences", limit: int = 10) -> list[str]:
    """The different lines of ``counts`` (line -> how many of ``total`` sequences, or other
    ``unit``, have it), most frequent first, each with its count unless every one has it; at most
    ``limit`` of them and a last line counting the others (one line per sequence would be thousands)."""
    ranked = sorted(counts.items(), key=lambda item: (-item[1], item[0]))
    out = [line if n == total else f"{line} ({n:,} of {total:,} {unit})" for line, n in ranked[:limit]]
    if len(ranked) > limit:
        out.append(f"and {len(ranked) - limit:,} more")
    return out


def _intact_files(folder, sequences: Mapping[str, Sequence]
                  ) -> tuple[dict[str, Path], list[str], dict[str, dict | None]]:
    """The result files of ``folder``, apart the sequences whose dcfkit sidecar says the file is
    damaged or stale (:meth:`~dcfkit.store.results.ResultStore.stale`: made from another first
    box or on other data than ``sequences`` now hold; never compared, each logged), and each
    file's platform record (None without one).
    Files without a sidecar are taken as they are; reset-based runs are refused
    (:func:`~dcfkit.analysis.report.refuse_reset_runs`)."""
    files, store = result_files(folder), ResultStore(folder)
    damaged, platform_records = [], {}
    metas = {name: store.sidecar(name) for name in files}
    refuse_reset_runs(Path(folder), [name for name, meta in metas.items()
                                     if isinstance(meta, dict) and meta.get("resets") is not None])
    for name in list(files):
        meta = metas[name]
        record = meta.get("platform") if isinstance(meta, dict) else None
        platform_records[name] = record if isinstance(record, dict) else None
        problem = store.problem(name, meta) if meta is not None else None
        if problem is None and meta is not None and name in sequences:
            problem = store.stale(name, meta, sequences[name])
        if problem is not None:
            log.warning("%s: left out of the comparison", problem)
            damaged.append(files.pop(name))
    return files, [p.stem for p in damaged], platform_records


def _what(exp: Experiment) -> str:
    return f"all its {exp.name.upper()} runs" if exp.pooled else "results"


def _compared(seq: Sequence, runs: list[Sequence], ours: Mapping[str, Path], theirs: Mapping[str, Path],
              proto: Protocol, divergence_px: float, pooled: bool) -> tuple[dict, dict, dict]:
    """(the row, the two scores) of ``seq`` from the files of its ``runs`` (the sequence itself
    in one pass): scores pooled over the runs, IoU over all their frames, the first divergence
    (``"k:f"`` where the experiment has runs, ``pooled``)."""
    found, found_ref, ious, diverges_at = [], [], [], None
    for k, run in enumerate(runs, 1):
        a, b = _boxes(run, ours[run.name], theirs[run.name])
        found.append(metrics.score_sequence(a, run.ground_truth, protocol=proto))
        found_ref.append(metrics.score_sequence(b, run.ground_truth, protocol=proto))
        ious.append(series_iou(a, b))
        frame = first_divergence(a, b, divergence_px)
        if diverges_at is None and frame is not None:
            diverges_at = f"{k}:{frame}" if pooled else frame
    s, s_ref = ((scores[0] if len(runs) == 1 else metrics.pool_runs(scores, proto)) for scores in (found, found_ref))
    frames = sum(len(run) for run in runs)
    return _row(seq.name, frames, s, s_ref, float(np.concatenate(ious).mean()), diverges_at), s, s_ref


def _boxes(seq: Sequence, path: Path, path_ref: Path) -> tuple[np.ndarray, np.ndarray]:
    a, b = read_boxes(path), read_boxes(path_ref)
    if len(a) != len(b):
        raise DatasetError(f"sequence {seq.name!r}: {path} has {len(a)} lines but {path_ref} has {len(b)}")
    if len(a) != len(seq):
        raise DatasetError(f"sequence {seq.name!r}: {path} and {path_ref} have {len(a)} lines but the "
                           f"sequence has {len(seq)} frames")
    return a, b


def _row(name: str, frames: int, s: dict, s_ref: dict, iou: float, diverges_at: int | str | None) -> dict:
    return {"sequence": name, "frames": frames,
            "precision": s["precision"], "precision_ref": s_ref["precision"],
            "d_precision": s["precision"] - s_ref["precision"],
            "auc": s["auc"], "auc_ref": s_ref["auc"], "d_auc": s["auc"] - s_ref["auc"],
            "iou": iou, "diverges_at": diverges_at}
