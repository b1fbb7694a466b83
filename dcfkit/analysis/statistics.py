"""How sure a score is: bootstrap confidence intervals of a mean over sequences and of a paired
difference, the Wilcoxon signed-rank test, and Holm's correction for several comparisons
(scipy.stats; docs/evaluation.md, "Statistics").

Sequences are the unit: a tracker's score on a benchmark is the mean of its per-sequence
scores, and two trackers are compared on the sequences both ran, sequence by sequence.
Resampling is seeded, so the same scores always give the same intervals. Values closer than
``TIE_TOLERANCE`` of the scores' largest magnitude count as equal (docs/evaluation.md, "Ties"),
so that a change in a score's last bit cannot move an interval or a p value.
"""
from __future__ import annotations

import dataclasses
import math
from typing import Sequence

import numpy as np
from scipy import special, stats

from dcfkit.analysis.stats.columns import DIFFERENCE, MEAN, computed
from dcfkit.analysis.stats.results import Comparison, Corrected, Difference, Interval

__all__ = ["Comparison", "Corrected", "Difference", "Interval", "holm", "mean_interval", "paired_difference",
           "versus_baseline", "wilcoxon_p"]

CONFIDENCE = 0.95
RESAMPLES = 10_000
SEED = 0
BATCH = 2 ** 21  # indices drawn at a time by the bootstrap (16 MiB): memory O(n), not O(RESAMPLES n)
#: Relative to the scores' largest magnitude: resampled means, and paired differences, closer
#: than this count as equal. 300 times the rounding error bound of a float mean of a million
#: scores (numpy's pairwise sum: about 3e-15), and a thousandth of the smallest gap between a
#: resampled mean and the mean of scores 0.5 +- 1e-4 (2e-9 with 6 to 39 scores).
TIE_TOLERANCE = 1e-12
METHOD = (f"{CONFIDENCE:.0%} BCa bootstrap confidence intervals over sequences ({RESAMPLES:,} resamples, "
          f"seed {SEED}); paired differences A - B per sequence with the two-sided Wilcoxon signed-rank p "
          f"(zero differences dropped); values within {TIE_TOLERANCE:g} of the scores' scale tie")
HOLM = "p Holm-corrected across the comparisons shown; significant: corrected p < 0.05"


def mean_interval(values: Sequence[float]) -> Interval:
    """The mean of the finite ``values`` and its BCa bootstrap interval, with the statistics added
    to the declaration (:func:`~dcfkit.analysis.stats.columns.computed`) in ``extra``."""
    x = _finite(values)
    return dataclasses.replace(_interval(x, _tolerance(x)), extra=computed(MEAN, x))


def _interval(x: np.ndarray, tolerance: float) -> Interval:
    if len(x) == 0:
        return Interval(math.nan, math.nan, math.nan, 0)
    low, high = _bootstrap(x, tolerance)
    return Interval(float(x.mean()), low, high, len(x))


def paired_difference(a: Sequence[float], b: Sequence[float]) -> Difference:
    """``a - b`` per sequence (pairs with a non-finite value left out): mean, bootstrap
    interval, Wilcoxon signed-rank p (1 when every difference is zero) and won/lost/tied, with
    differences within ``TIE_TOLERANCE`` of the scores' scale tied (:func:`_tied`)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    if a.shape != b.shape or a.ndim != 1:
        raise ValueError(f"paired scores need two sequences of one length, got shapes {a.shape} and {b.shape}")
    finite = np.isfinite(a) & np.isfinite(b)
    d = (a - b)[finite]
    # the scale is the scores', not the differences': a score's last bit moves its difference by that much
    tolerance = _tolerance(np.r_[a[finite], b[finite]])
    interval, ranked = _interval(d, tolerance), _tied(d, tolerance)
    return Difference(interval.mean, interval.ci_low, interval.ci_high, interval.n, wilcoxon_p(ranked),
                      int((ranked > 0).sum()), int((ranked < 0).sum()), int((ranked == 0).sum()),
                      extra=computed(DIFFERENCE, a[finite], b[finite]))


def wilcoxon_p(differences: np.ndarray) -> float:
    """Two-sided Wilcoxon signed-rank p of ``differences`` (zeros dropped); 1 if none is left,
    NaN if there are none at all."""
    if len(differences) == 0:
        return math.nan
    if not np.any(differences):
        return 1.0
    return float(stats.wilcoxon(differences, zero_method="wilcox", alternative="two-sided").pvalue)


def holm(pvalues: Sequence[float]) -> list[float]:
    """Holm's step-down adjustment of ``pvalues`` (NaN entries stay NaN and are not counted):
    the k-th smallest of m becomes max over j <= k of min(1, (m - j + 1) p_(j)). scipy.stats
    has Benjamini-Hochberg (false_discovery_control), not Holm."""
    p = np.asarray(pvalues, dtype=float)
    out = np.full(p.shape, math.nan)
    valid = np.flatnonzero(np.isfinite(p))
    running = 0.0
    for rank, i in enumerate(valid[np.argsort(p[valid], kind="stable")]):
        running = max(running, min(1.0, (len(valid) - rank) * p[i]))
        out[i] = running
    return out.tolist()


def _finite(values: Sequence[float]) -> np.ndarray:
    x = np.asarray(values, dtype=float).ravel()
    return x[np.isfinite(x)]


def _tolerance(scores: np.ndarray) -> float:
    """``TIE_TOLERANCE`` times the largest magnitude of ``scores`` (0 for none)."""
    return TIE_TOLERANCE * float(np.max(np.abs(scores))) if len(scores) else 0.0


def _tied(d: np.ndarray, tolerance: float) -> np.ndarray:
    """``d`` with ties made exact: differences within ``tolerance`` of 0 set to 0, and
    magnitudes within ``tolerance`` of the next smaller one set to the smallest of their run
    (signs kept), so that Wilcoxon's ranks, average ranks of ties and zeros dropped, and
    scipy's choice of exact or approximate p, do not depend on the differences' last bits."""
    if len(d) == 0:
        return d
    magnitude = np.where(np.abs(d) <= tolerance, 0.0, np.abs(d))
    order = np.argsort(magnitude, kind="stable")
    sorted_magnitude = magnitude[order]
    run_starts = np.r_[True, np.diff(sorted_magnitude) > tolerance]
    tied = np.empty_like(magnitude)
    tied[order] = sorted_magnitude[run_starts][np.cumsum(run_starts) - 1]
    return np.sign(d) * tied


def _bootstrap(x: np.ndarray, tolerance: float) -> tuple[float, float]:
    """The BCa interval of the mean of ``x``, as ``scipy.stats.bootstrap(method="BCa")`` gives it
    with this module's settings where no resampled mean is within ``tolerance`` of the sample
    mean (else see :func:`_bca_levels`), or (BCa undefined) its percentile interval: NaN for
    one value, the value itself when all are equal (no spread to resample)."""
    if len(x) < 2:
        return math.nan, math.nan
    if np.all(x == x[0]):
        return float(x[0]), float(x[0])
    means = _bootstrap_means(x)
    alpha = (1 - CONFIDENCE) / 2
    with np.errstate(invalid="ignore", divide="ignore"):
        ci = stats.quantile(means, np.array(_bca_levels(x, means, alpha, tolerance)))
    if not np.all(np.isfinite(ci)):  # BCa undefined: the percentile interval (scipy's draws the same resamples)
        ci = stats.quantile(means, np.array([alpha, 1 - alpha]))
    return float(ci[0]), float(ci[1])


def _bootstrap_means(x: np.ndarray) -> np.ndarray:
    """``(RESAMPLES,)`` means of resamples of ``x``: scipy.stats.bootstrap's draws (one
    ``integers(0, n, (RESAMPLES, n))`` of a generator seeded ``SEED``), drawn in batches of rows
    so that memory stays O(n) (the draws come out the same, row after row)."""
    rng, n = np.random.default_rng(SEED), len(x)
    rows = max(1, BATCH // n)
    return np.concatenate([np.mean(x[rng.integers(0, n, (min(rows, RESAMPLES - k), n))], axis=-1)
                           for k in range(0, RESAMPLES, rows)])


def _bca_levels(x: np.ndarray, means: np.ndarray, alpha: float, tolerance: float) -> tuple[float, float]:
    """The BCa levels (alpha_1, alpha_2) of Efron & Tibshirani (1993) Eq. (14.10), (14.14)-(14.15),
    computed as scipy's ``_bca_interval``, with the jackknife means of a mean in closed form:
    mean + (mean - x_i) / (n - 1), not n resamples of n - 1 values. The bias correction z0 of
    Eq. (14.14) counts a resampled mean within ``tolerance`` of the sample mean as half below
    it (mid-rank), as scipy counts one exactly equal: resamples of the same multiset tie in
    exact arithmetic, and the float sum's order must not decide on which side they fall."""
    n, mean = len(x), np.mean(x)
    below = np.count_nonzero(means < mean - tolerance)
    tied = np.count_nonzero(np.abs(means - mean) <= tolerance)
    z0 = special.ndtri((2 * below + tied) / (2 * len(means)))
    jackknife = mean + (mean - x) / (n - 1)
    u = (n - 1) * (np.mean(jackknife) - jackknife)
    a = 1 / 6 * (np.sum(u ** 3) / n ** 3) / (np.sum(u ** 2) / n ** 2) ** (3 / 2)
    z = float(special.ndtri(alpha))
    return tuple(float(special.ndtr(z0 + (z0 + zk) / (1 - a * (z0 + zk)))) for zk in (z, -z))


def versus_baseline(per_sequence: Sequence[dict], trackers: Sequence[str], keys: Sequence[str],
                    baseline: str | None = None) -> Comparison:
    """Each tracker's mean of each score in ``keys`` with its interval, over the sequences every
    tracker has a row for, and each other tracker's paired difference from ``baseline`` (by
    default the first tracker), its Wilcoxon p Holm-corrected per score across the trackers.

    ``per_sequence`` rows have ``tracker``, ``sequence`` and the scores. Returns a
    :class:`Comparison`: ``sequences`` (how many), ``means`` (tracker -> score -> :class:`Interval`),
    ``differences`` (tracker -> score -> :class:`Corrected`) and ``non_finite`` (tracker -> score ->
    the sequences left out of its mean and differences for a non-finite score; only those with any).
    """
    baseline = baseline if baseline is not None else trackers[0]
    table: dict[str, dict[str, dict]] = {t: {} for t in trackers}
    for row in per_sequence:
        if row["tracker"] in table:
            table[row["tracker"]][row["sequence"]] = row
    shared = [s for s in table[baseline] if all(s in table[t] for t in trackers)]
    scores = {t: {k: [table[t][s][k] for s in shared] for k in keys} for t in trackers}
    others = [t for t in trackers if t != baseline]
    differences: dict[str, dict] = {t: {} for t in others}
    for key in keys:
        found = [paired_difference(scores[t][key], scores[baseline][key]) for t in others]
        for t, d, p in zip(others, found, holm([d.wilcoxon_p for d in found])):
            differences[t][key] = Corrected.of(d, p, bool(p < 0.05))
    non_finite = {t: {k: [s for s, bad in zip(shared, ~np.isfinite(np.asarray(scores[t][k], dtype=float))) if bad]
                      for k in keys} for t in trackers}
    return Comparison(METHOD, HOLM, baseline, len(shared),
                      means={t: {k: mean_interval(scores[t][k]) for k in keys} for t in trackers},
                      differences=differences,
                      non_finite={t: {k: v for k, v in found.items() if v} for t, found in non_finite.items()
                                  if any(found.values())})
