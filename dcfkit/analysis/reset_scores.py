"""Scores of VOT's reset-based experiment (:mod:`dcfkit.experiments.vot`): accuracy,
robustness and the expected average overlap (EAO), as VOT2016 defines them (Kristan et al.,
TPAMI 2016; docs/evaluation.md, "Reset-based experiment").

Overlaps are those of the run's :class:`~dcfkit.experiments.vot.ResetRule` (the rule that
decided its failures): VOT2016's averages unbounded overlaps in the accuracy and overlaps
inside the image in the EAO, vot-toolkit's the same in both. As the VOT2016 (MATLAB) toolkit
computes them (``estimate_accuracy.m``,
``estimate_expected_overlap.m``, ``analyze_average_expected_overlap.m``):

* **Accuracy**: the mean overlap of the tracked frames, leaving out the
  :data:`~dcfkit.experiments.vot.BURN_IN` frames from each start and the failure frames;
  a benchmark's pools the frames of all sequences (each sequence's own accuracy feeds the
  statistics).
* **Robustness**: failures, per sequence and in all.
* **EAO**: each start begins a fragment that runs to the next start (its overlap 0 from the
  failure on, and after its end) or, the last, to the sequence's end (nothing after it).
  ``Φ(Ns)`` is the mean over the fragments that reach length ``Ns`` (padded ones always) of
  their mean overlap over the ``Ns - 1`` frames after the start (``Φ(1)`` is 1, as the toolkit
  defines it: no frame after the start); the EAO is the mean of ``Φ(Ns)`` for ``Ns`` in
  ``[low, high]``, both included (:func:`eao_interval`). An interval of ``Ns = 1`` alone (one-frame
  sequences) averages no tracked frame: its EAO is NaN, where the toolkit's definition of ``Φ(1)``
  gives 1 (and the VOT Python toolkit's, 0).
"""
from __future__ import annotations

import dataclasses
import functools
import math
import warnings
from typing import Mapping, Sequence

import numpy as np
from scipy import stats

from dcfkit.analysis import statistics
from dcfkit.analysis.scoring import check_baseline
from dcfkit.experiments.vot import BURN_IN, DEFAULT_RULE, get_rule

__all__ = ["ResetRun", "eao", "eao_interval", "expected_overlaps", "fragments", "pooled_accuracy", "score_resets",
           "sequence_scores"]


@dataclasses.dataclass(frozen=True)
class ResetRun:
    """One reset-based run: ``boxes`` ``(N, 4)`` 0-based (NaN where not tracked), the ground
    truth ``gt``, the 0-based ``starts`` and ``failures``, the image ``bounds``
    ``(width, height)`` (None: not cut) and the name of the ``rule`` that decided its failures."""

    boxes: np.ndarray
    gt: np.ndarray
    starts: tuple[int, ...]
    failures: tuple[int, ...]
    bounds: tuple[float, float] | None = None
    rule: str = DEFAULT_RULE

    def _overlaps(self, overlap) -> np.ndarray:
        """Each frame's ``overlap`` with the ground truth (NaN where either is missing)."""
        out = np.full(len(self.gt), np.nan)
        tracked = np.isfinite(self.boxes).all(axis=1)
        if tracked.any():
            out[tracked] = overlap(self.boxes[tracked], self.gt[tracked], self.bounds)
        return out

    @functools.cached_property
    def overlaps(self) -> np.ndarray:
        """Each frame's overlap as the rule's EAO takes it; computed once, read by the fragments."""
        return self._overlaps(get_rule(self.rule).eao)

    @functools.cached_property
    def accuracy_overlaps(self) -> np.ndarray:
        """Each frame's overlap as the rule's accuracy takes it."""
        return self._overlaps(get_rule(self.rule).accuracy)


def _accuracy_frames(run: ResetRun) -> tuple[np.ndarray, np.ndarray]:
    """(each frame's overlap, whether it counts in the accuracy)."""
    o = run.accuracy_overlaps
    counted = np.isfinite(o)
    for start in run.starts:
        counted[start:start + BURN_IN] = False
    counted[list(run.failures)] = False
    return o, counted


def sequence_scores(run: ResetRun) -> dict:
    """``accuracy`` (NaN when no frame counts), ``failures`` and ``frames`` (those in the accuracy)."""
    o, counted = _accuracy_frames(run)
    return {"accuracy": float(o[counted].mean()) if counted.any() else math.nan,
            "failures": len(run.failures), "frames": int(counted.sum())}


def pooled_accuracy(runs: Sequence[ResetRun]) -> float:
    """The accuracy of the frames of all ``runs`` pooled (NaN when none counts)."""
    found = [_accuracy_frames(run) for run in runs]
    values = np.concatenate([o[counted] for o, counted in found]) if found else np.empty(0)
    return float(values.mean()) if values.size else math.nan


def fragments(run: ResetRun) -> list[tuple[np.ndarray, bool]]:
    """``(overlaps from the start on, padded)`` of each start: to its failure, padded with
    zeros, when the tracker was started again; the last to the sequence's end, not padded. A
    frame without an overlap (not tracked, no ground truth) counts 0."""
    o = np.nan_to_num(run.overlaps, nan=0.0)
    last = len(run.starts) - 1
    return [(o[s:run.failures[k] + 1], True) if k < last else (o[s:], False) for k, s in enumerate(run.starts)]


def _sums(frags: Sequence[tuple[np.ndarray, bool]], lengths: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(sum over fragments of their mean overlap after the start, fragments counted) per ``Ns``."""
    total, count = np.zeros(len(lengths)), np.zeros(len(lengths))
    for o, failed in frags:
        after = np.cumsum(o[1:])  # after[k - 1]: the first k frames after the start
        for j, ns in enumerate(lengths):
            k = ns - 1
            if k <= len(after):
                total[j] += after[k - 1] / k if k else 1.0
                count[j] += 1
            elif failed:  # zero from its failure on
                total[j] += (after[-1] if len(after) else 0.0) / k
                count[j] += 1
    return total, count


def _run_sums(runs: Sequence[ResetRun], lengths: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_sums` of each run: ``(total, count)``, each ``(runs, lengths)``."""
    found = [_sums(fragments(run), lengths) for run in runs]
    shape = (len(found), len(lengths))
    return (np.array([t for t, _ in found]).reshape(shape), np.array([c for _, c in found]).reshape(shape))


def _phi(total: np.ndarray, count: np.ndarray) -> np.ndarray:
    """``Φ`` from the summed mean overlaps and fragment counts; NaN where no fragment counts."""
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(count > 0, total / np.maximum(count, 1), np.nan)


def expected_overlaps(runs: Sequence[ResetRun], lengths: Sequence[int]) -> np.ndarray:
    """``Φ(Ns)`` for each sequence length ``Ns`` (>= 1) in ``lengths``; NaN where no fragment counts."""
    total, count = _run_sums(runs, np.asarray(lengths, dtype=int))
    return _phi(total.sum(axis=0), count.sum(axis=0))


def eao_interval(lengths: Sequence[int], mass: float = 0.5) -> tuple[int, int]:
    """``[low, high]`` as the VOT2016 toolkit's ``estimate_evaluation_interval``: the density
    of the sequence ``lengths`` on ``1..max`` (a Gaussian KDE; scipy's Scott bandwidth where
    the toolkit uses its own plug-in rule), normalised; from its mode, one length at a time
    toward the denser side (the longer on a tie) until the interval holds ``mass``."""
    x = np.asarray(lengths, dtype=float)
    if len(x) < 2 or np.all(x == x[0]):
        return int(x[0]), int(x[0])
    density = stats.gaussian_kde(x)(np.arange(1, int(x.max()) + 1))
    density /= density.sum()
    lo = hi = int(np.argmax(density))
    while density[lo:hi + 1].sum() < mass and (lo > 0 or hi < len(density) - 1):
        left = density[lo - 1] if lo > 0 else -math.inf
        right = density[hi + 1] if hi < len(density) - 1 else -math.inf
        if right >= left:
            hi += 1
        else:
            lo -= 1
    return lo + 1, hi + 1


def _mean_phi(phi: np.ndarray) -> float:
    return float(np.nanmean(phi)) if np.isfinite(phi).any() else math.nan


def eao(runs: Sequence[ResetRun], interval: tuple[int, int]) -> float:
    """The mean of ``Φ(Ns)`` over ``Ns`` in ``interval`` (both ends included); NaN for ``(1, 1)``."""
    if interval[1] < 2:
        return math.nan  # no frame tracked: Φ(1) is 1 by definition, not by a tracker
    return _mean_phi(expected_overlaps(runs, range(interval[0], interval[1] + 1)))


def _eao_with_ci(runs: Sequence[ResetRun], interval: tuple[int, int]) -> tuple[float, float, float]:
    """(the EAO, its percentile bootstrap interval over sequences) with statistics' settings,
    from one pass over the runs; the interval of the resamples that have an EAO (one of
    sequences all shorter than the interval has none)."""
    if interval[1] < 2:
        return eao(runs, interval), math.nan, math.nan
    total, count = _run_sums(runs, np.arange(interval[0], interval[1] + 1))
    point = _mean_phi(_phi(total.sum(axis=0), count.sum(axis=0)))
    if len(runs) < 2:
        return point, math.nan, math.nan

    def statistic(index, axis=-1):
        index = np.asarray(index, dtype=int)
        return np.nanmean(_phi(total[index].sum(axis=-2), count[index].sum(axis=-2)), axis=-1)

    with warnings.catch_warnings():  # a resample of sequences all too short for the interval has no EAO
        warnings.simplefilter("ignore", (stats.DegenerateDataWarning, RuntimeWarning))
        found = stats.bootstrap((np.arange(len(runs)),), statistic, confidence_level=statistics.CONFIDENCE,
                                n_resamples=statistics.RESAMPLES, method="percentile", vectorized=True,
                                batch=max(1, statistics.BATCH // total.size),  # memory O(runs), not O(resamples runs)
                                rng=np.random.default_rng(statistics.SEED)).bootstrap_distribution
    found = found[np.isfinite(found)]  # scipy's percentile interval is NaN if one resample is: those are left out
    if not found.size:
        return point, math.nan, math.nan
    tail = (1 - statistics.CONFIDENCE) / 2 * 100
    low, high = np.percentile(found, [tail, 100 - tail])
    return point, float(low), float(high)


def score_resets(results: Mapping[str, Mapping[str, ResetRun]], lengths: Mapping[str, int],
                 interval: tuple[int, int] | None = None, baseline: str | None = None) -> dict:
    """Score each tracker's runs (tracker -> sequence -> :class:`ResetRun`) on the sequences
    every tracker ran; ``lengths`` are all sequences' lengths, for the EAO interval (by
    default :func:`eao_interval` of them). Returns plain data: ``interval``, ``overall`` rows
    (``tracker``, ``accuracy``, ``failures``, ``eao`` with ``eao_ci_low`` and ``eao_ci_high``, ``sequences``, best EAO
    first), ``per_sequence`` rows, ``left_out`` (sequence -> the trackers without its run) and ``statistics``
    (:func:`~dcfkit.analysis.statistics.versus_baseline` of accuracy and failures, from ``baseline``,
    by default the best)."""
    interval = interval or eao_interval(list(lengths.values()))
    names = [s for s in lengths if all(s in res for res in results.values())]
    left_out = {s: [t for t, res in results.items() if s not in res] for s in lengths if s not in names}
    per_sequence, overall = [], []
    for tracker, res in results.items():
        rows = [{"tracker": tracker, "sequence": s, **sequence_scores(res[s])} for s in names]
        per_sequence += rows
        runs = [res[s] for s in names]
        found = dict(zip(("eao", "eao_ci_low", "eao_ci_high"), _eao_with_ci(runs, interval)))
        overall.append({"tracker": tracker, "accuracy": pooled_accuracy(runs),
                        "failures": sum(r["failures"] for r in rows), **found, "sequences": len(rows)})
    overall.sort(key=lambda r: -r["eao"] if math.isfinite(r["eao"]) else math.inf)
    ranked = [r["tracker"] for r in overall]
    check_baseline(baseline, ranked)
    return {"interval": list(interval), "overall": overall, "per_sequence": per_sequence, "left_out": left_out,
            "statistics": statistics.versus_baseline(per_sequence, ranked, ("accuracy", "failures"), baseline)
            if ranked else {}}
