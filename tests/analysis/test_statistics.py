"""The statistics of comparisons: scipy's bootstrap and Wilcoxon on hand-made score tables,
hand-computed cases, and Holm's correction against its definition."""
from __future__ import annotations

import itertools
import math
import tracemalloc
import warnings

import numpy as np
import pytest
from hypothesis import assume, given
from hypothesis import strategies as st
from scipy import stats

from dcfkit.analysis import statistics
from dcfkit.analysis.statistics import RESAMPLES, SEED, holm, mean_interval, paired_difference, wilcoxon_p

# per-sequence AUCs of two trackers on eight sequences (a hand-made table)
A = np.array([0.612, 0.455, 0.301, 0.702, 0.518, 0.390, 0.444, 0.587])
B = np.array([0.598, 0.470, 0.262, 0.650, 0.518, 0.341, 0.401, 0.560])


def test_the_interval_of_a_mean_is_scipys_bca_bootstrap():
    got = mean_interval(A)
    low, high = _exact_ties_interval(A)  # in units of 0.001: 24 resampled means tie the mean
    assert (got.mean, got.ci_low, got.ci_high, got.n) == (pytest.approx(A.mean()), pytest.approx(low, abs=1e-12),
                                                          pytest.approx(high, abs=1e-12), 8)
    assert got.ci_low < got.mean < got.ci_high


def test_a_paired_difference_is_the_bootstrap_and_wilcoxon_of_the_differences():
    d = paired_difference(A, B)
    low, high = _exact_ties_interval(A - B)
    assert (d.mean, d.ci_low, d.ci_high) == (pytest.approx((A - B).mean()), pytest.approx(low, abs=1e-12),
                                             pytest.approx(high, abs=1e-12))
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


def _resampled_gaps(x: np.ndarray) -> np.ndarray:
    """How far each of scipy's resampled means is from the sample mean, in units of the tie tolerance."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", stats.DegenerateDataWarning)
        means = stats.bootstrap((x,), np.mean, n_resamples=RESAMPLES, method="percentile",
                                rng=np.random.default_rng(SEED)).bootstrap_distribution
    return np.abs(means - np.mean(x)) / (statistics.TIE_TOLERANCE * np.max(np.abs(x)))


def _grid(x: np.ndarray) -> float | None:
    """The unit of the decimal grid ``x`` lies on (1, 0.25, 0.1 or 0.001), if any."""
    return next((unit for unit in (1.0, 0.25, 0.1, 0.001)
                 if np.allclose(x / unit, np.round(x / unit), rtol=0, atol=1e-9)), None)


def _exact_ties_interval(x: np.ndarray) -> tuple[float, float]:
    """scipy's BCa interval where resampled means equal in exact arithmetic are equal floats, so
    that scipy counts them half below the sample mean: scores on a decimal grid counted in its
    units (integers, whose float sums are exact) and scaled back; other scores' means from
    correctly rounded sums (math.fsum), equal for equal multisets."""
    unit = _grid(x)
    if unit is not None:
        low, high = _scipy_interval(np.round(x / unit))
        return low * unit, high * unit
    exact_mean = lambda v, axis: np.apply_along_axis(math.fsum, axis, v) / v.shape[axis]  # noqa: E731
    ci = stats.bootstrap((x,), exact_mean, n_resamples=RESAMPLES, method="BCa",
                         rng=np.random.default_rng(SEED)).confidence_interval
    return float(ci.low), float(ci.high)


@pytest.mark.parametrize("x", _tables(40), ids=lambda x: f"n{len(x)}")
def test_the_interval_is_scipys_bca_on_small_tables(x):
    """scipy's interval with ties exact; and scipy's own where its float sums tie what ties
    (no resampled mean within the tie tolerance of the sample mean but not equal to it)."""
    got = (mean_interval(x).ci_low, mean_interval(x).ci_high)
    assert got == pytest.approx(_exact_ties_interval(x), abs=1e-12, rel=0)
    gaps = _resampled_gaps(x)
    if not np.any((gaps > 0) & (gaps <= 1)):
        assert got == pytest.approx(_scipy_interval(x), abs=1e-12, rel=0)


def test_the_small_tables_hold_near_ties_and_none():
    near = [np.any((gap > 0) & (gap <= 1)) for gap in map(_resampled_gaps, _tables(40))]
    assert any(near) and not all(near)


# six per-sequence AUCs (BACF's on the development sequences, docs/results.md): 166 of the
# 10,000 resampled means are the sample's multiset again, equal to its mean short of last bits
SIX = np.array([0.779, 0.718, 0.422, 0.588, 0.569, 0.305])


def _last_bit_changes(x: np.ndarray):
    """``x`` with one score moved by one ulp up or down, each score and direction in turn."""
    for i, direction in itertools.product(range(len(x)), (np.inf, -np.inf)):
        y = x.copy()
        y[i] = np.nextafter(y[i], direction)
        yield y


def _largest_move(x: np.ndarray) -> float:
    base = mean_interval(x)
    return max(max(abs(got.ci_low - base.ci_low), abs(got.ci_high - base.ci_high))
               for got in map(mean_interval, _last_bit_changes(x)))


def test_a_last_bit_change_in_a_score_does_not_move_the_interval():
    assert np.count_nonzero(_resampled_gaps(SIX) <= 1) == 166  # without the tie rule a bound moved by 0.0076
    assert _largest_move(SIX) < 1e-12 * np.max(np.abs(SIX))


@given(st.lists(st.integers(0, 1000), min_size=2, max_size=9), st.sampled_from([1e-3, 0.1, 1.0, 250.0]))
def test_no_last_bit_change_moves_an_interval(counts, unit):
    """Scores on a decimal grid (AUCs to 3 decimals, failure counts, ...): many ties."""
    assume(any(counts))
    x = np.array(counts) * unit
    assert _largest_move(x) <= 1e-12 * np.max(np.abs(x))


def test_a_last_bit_change_in_a_score_does_not_move_a_paired_difference():
    other = np.array([0.763, 0.725, 0.613, 0.793, 0.636, 0.534])  # DR²Track's AUCs beside SIX
    for a, b in [(SIX, other), (other + [0.05, 0, 0, 0, 0.01, 0.01], other)]:  # the second: 3 zeros, 2 tied
        base = paired_difference(a, b)
        for changed in itertools.chain(((y, b) for y in _last_bit_changes(a)), ((a, y) for y in _last_bit_changes(b))):
            got = paired_difference(*changed)
            assert (got.wilcoxon_p, got.won, got.lost, got.tied) == (base.wilcoxon_p, base.won, base.lost, base.tied)
            assert max(abs(got.ci_low - base.ci_low), abs(got.ci_high - base.ci_high)) < 1e-12


def test_differences_that_tie_in_decimals_are_tied_ranks():
    # 0.612 - 0.598 and 0.330 - 0.344 are +-0.014, 6e-17 apart in binary: one average rank, as
    # scipy gives the differences written exactly (in units of 0.001); by their bits 0.125
    d = paired_difference([0.612, 0.330, 0.301, 0.702, 0.5, 0.47], [0.598, 0.344, 0.262, 0.650, 0.5, 0.4])
    exact = stats.wilcoxon([14, -14, 39, 52, 70]).pvalue
    assert (d.wilcoxon_p, d.won, d.lost, d.tied) == (pytest.approx(exact), 4, 1, 1)
