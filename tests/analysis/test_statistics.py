"""The statistics of comparisons: scipy's bootstrap and Wilcoxon on hand-made score tables,
hand-computed cases, and Holm's correction against its definition."""
from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from scipy import stats

from dcfkit.analysis.statistics import RESAMPLES, SEED, holm, mean_interval, paired_difference, wilcoxon_p

# per-sequence AUCs of two trackers on eight sequences (a hand-made table)
A = np.array([0.612, 0.455, 0.301, 0.702, 0.518, 0.390, 0.444, 0.587])
B = np.array([0.598, 0.470, 0.262, 0.650, 0.518, 0.341, 0.401, 0.560])


def test_the_interval_of_a_mean_is_scipys_bca_bootstrap():
    got = mean_interval(A)
    ci = stats.bootstrap((A,), np.mean, n_resamples=RESAMPLES, method="BCa",
                         rng=np.random.default_rng(SEED)).confidence_interval
    assert (got.mean, got.ci_low, got.ci_high, got.n) == (pytest.approx(A.mean()), ci.low, ci.high, 8)
    assert got.ci_low < got.mean < got.ci_high


def test_a_paired_difference_is_the_bootstrap_and_wilcoxon_of_the_differences():
    d = paired_difference(A, B)
    ci = stats.bootstrap((A - B,), np.mean, n_resamples=RESAMPLES, method="BCa",
                         rng=np.random.default_rng(SEED)).confidence_interval
    assert (d.mean, d.ci_low, d.ci_high) == (pytest.approx((A - B).mean()), ci.low, ci.high)
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
