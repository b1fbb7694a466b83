"""The statistics of comparisons: scipy's bootstrap and Wilcoxon on hand-made score tables,
hand-computed cases, and Holm's correction against its definition."""
from __future__ import annotations

import itertools
import math
import tracemalloc
import warnings

import numpy as np
import pytest
from scipy import stats

from dcfkit.analysis import statistics
from dcfkit.analysis.statistics import RESAMPLES, SEED, holm, mean_interval, paired_difference, wilcoxon_p

# per-sequence AUCs of two trackers on eight sequences (a hand-made table)
A = np.array([0.612, 0.455, 0.301, 0.702, 0.518, 0.390, 0.444, 0.587])
B = np.array([0.598, 0.470, 0.262, 0.650, 0.518, 0.341, 0.401, 0.560])


def test_the_interval_of_a_mean_is_scipys_bca_bootstrap():
    got = mean_interval(A)
    ci = stats.bootstrap((A,), np.mean, n_resamples=RESAMPLES, method="BCa",
                         rng=np.random.default_rng(SEED)).confidence_interval
    assert (got.mean, got.ci_low, got.ci_high, got.n) == (pytest.approx(A.mean()), pytest.approx(ci.low, abs=1e-12),
                                                          pytest.approx(ci.high, abs=1e-12), 8)
    assert got.ci_low < got.mean < got.ci_high


def test_a_paired_difference_is_the_bootstrap_and_wilcoxon_of_the_differences():
    d = paired_difference(A, B)
    ci = stats.bootstrap((A - B,), np.mean, n_resamples=RESAMPLES, method="BCa",
                         rng=np.random.default_rng(SEED)).confidence_interval
    assert (d.mean, d.ci_low, d.ci_high) == (pytest.approx((A - B).mean()), pytest.approx(ci.low, abs=1e-12),
                                             pytest.approx(ci.high, abs=1e-12))
    assert d.wilcoxon_p == pytest.approx(stats.wilcoxon(A - B).pvalue)  # the zero of sequence 5 dropped
    assert (d.won, d.lost, d.tied, d.n) == (6, 1, 1, 8)


def test_hand_computed_two_sequences():
    # differences 0.2 and 0.3: the bootstrap means are 0.2, 0.25, 0.3 (1/4, 1/2, 1/4), so the
    # 95% interval is [0.2, 0.3]; Wilcoxon: both ranks positive, W+ = 3 of the 4 equally likely
    # sign patterns' {0, 1, 2, 3}, two-sided p = 2 * 1/4
    d = paired_difference([0.5, 0.4], [0.3, 0.1])
    assert (d.mean, d.ci_low, d.ci_high) == (pytest.approx(0.25), pytest.approx(0.2), pytest.approx(0.3))
    assert d.wilcoxon_p == pytest.approx(0.5) and (d.won, d.lost, d.tied) == (2, 0, 0)


def test_degenerate_tables():
    same = mean_interval([0.5, 0.5, 0.5])
    assert (same.mean, same.ci_low, same.ci_high) == (0.5, 0.5, 0.5)
    one = mean_interval([0.4])
    assert one.mean == 0.4 and math.isnan(one.ci_low) and math.isnan(one.ci_high)
    assert mean_interval([]).n == 0 and math.isnan(mean_interval([]).mean)
    equal = paired_difference([0.3, 0.4], [0.3, 0.4])
    assert equal.wilcoxon_p == 1 and equal.tied == 2 and equal.mean == 0
    missing = paired_difference([0.3, np.nan, 0.5], [0.1, 0.2, np.nan])  # pairs with a NaN left out
    assert missing.n == 1 and missing.won == 1 and math.isnan(wilcoxon_p(np.array([])))
    with pytest.raises(ValueError, match="one length"):
        paired_difference([0.1, 0.2], [0.1])


def _holm_by_definition(p):
    """Holm as a step-down test: the smallest p is compared with alpha/m, the next with
    alpha/(m-1), ...; the adjusted p is the least alpha at which each is rejected."""
    m = len(p)
    alphas = sorted({min(1.0, x) for x in itertools.chain(p, [(m - k) * q for k in range(m) for q in p])})
    out = []
    for i in range(m):
        for alpha in alphas:
            order = sorted(range(m), key=lambda j: p[j])
            rejected = set()
            for k, j in enumerate(order):
                if p[j] * (m - k) > alpha:
                    break
                rejected.add(j)
            if i in rejected:
                out.append(alpha)
                break
        else:
            out.append(1.0)
    return out


@pytest.mark.parametrize("p", [[0.01, 0.04, 0.03], [0.2, 0.001, 0.6, 0.04], [0.5], [0.03, 0.03]])
def test_holm_matches_its_step_down_definition(p):
    assert holm(p) == pytest.approx(_holm_by_definition(p))


def test_holm_by_hand_and_with_missing_p():
    assert holm([0.01, 0.04, 0.03]) == pytest.approx([0.03, 0.06, 0.06])
    got = holm([0.01, math.nan, 0.04])
    assert got[0] == pytest.approx(0.02) and math.isnan(got[1]) and got[2] == pytest.approx(0.04)


def _scipy_interval(x: np.ndarray, method: str = "BCa") -> tuple[float, float]:
    """scipy.stats.bootstrap's interval of the mean with the module's settings (n x n jackknife
    and RESAMPLES x n resamples at once: the reference, for small n only)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", stats.DegenerateDataWarning)
        ci = stats.bootstrap((x,), np.mean, n_resamples=RESAMPLES, method=method,
                             rng=np.random.default_rng(SEED)).confidence_interval
    return float(ci.low), float(ci.high)


def _tables(count: int) -> list[np.ndarray]:
    """Small random score tables: continuous, few distinct values (ties), one outlier, a tiny spread."""
    rng = np.random.default_rng(7)
    kinds = [lambda n: rng.random(n), lambda n: rng.integers(0, 3, n) * 0.25, lambda n: np.r_[np.zeros(n - 1), 1.0],
             lambda n: 0.5 + 1e-4 * rng.normal(size=n), lambda n: np.round(rng.normal(size=n), 1)]
    return [kinds[k % len(kinds)](int(rng.integers(2, 40))) for k in range(count)] + [np.array([0.0, 1.0]),
                                                                                      np.array([0.3, 0.3, 0.9])]


@pytest.mark.parametrize("x", _tables(40), ids=lambda x: f"n{len(x)}")
def test_the_interval_is_scipys_bca_on_small_tables(x):
    got = mean_interval(x)
    assert (got.ci_low, got.ci_high) == pytest.approx(_scipy_interval(x), abs=1e-12, rel=0)


def test_where_bca_is_undefined_the_interval_is_scipys_percentile_one(monkeypatch):
    x = np.array([0.1, 0.4, 0.4, 0.35, 0.9])
    monkeypatch.setattr(statistics, "_bca_levels", lambda *args: (math.nan, math.nan))
    got = mean_interval(x)
    assert (got.ci_low, got.ci_high) == pytest.approx(_scipy_interval(x, "percentile"), abs=1e-12, rel=0)


def test_memory_does_not_grow_with_resamples_times_sequences():
    """scipy's BCa holds n x n jackknife indices and RESAMPLES x n resample indices: 480 MB at
    3,000 sequences (10 GB at 30,000); drawn in batches the peak is a few batches, whatever n."""
    rng = np.random.default_rng(1)
    a, b = rng.random(3000), rng.random(3000)
    tracemalloc.start()
    try:
        paired_difference(a, b)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak < 64 * 2 ** 20  # a few batches of 2 ** 21 int64 indices and their values; 480 MB at once
