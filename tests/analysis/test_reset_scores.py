"""Accuracy, robustness and EAO of reset-based runs, against cases worked out by hand from the
VOT2016 definitions (Kristan et al., TPAMI 2016; the VOT2016 toolkit's estimate_accuracy.m and
estimate_expected_overlap.m)."""
from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from dcfkit.analysis import reset_scores
from dcfkit.analysis.reset_scores import (
    eao,
    eao_interval,
    expected_overlaps,
    fragments,
    pooled_accuracy,
    score_resets,
    sequence_scores,
)
from dcfkit.datasets import DatasetError


def ResetRun(*args) -> reset_scores.ResetRun:  # noqa: N802
    """A run of whole-pixel boxes inside a 640x480 image under vot-toolkit's rule, whose overlap of
    such boxes is their continuous one: the cases' overlaps stay as worked out by hand."""
    return reset_scores.ResetRun(*args, bounds=(640, 480), rule="vot-toolkit")


GT_BOX = [10.0, 10.0, 10.0, 10.0]
HALF = [10.0, 10.0, 10.0, 5.0]  # overlap 0.5 with GT_BOX
AWAY = [50.0, 50.0, 10.0, 10.0]


def one_failure() -> ResetRun:
    """30 frames: overlap 1, 0.5 on frame 11, a failure on 12, frames 13-16 not tracked, a
    restart on 17 (12 + 5), overlap 1 to the end."""
    gt = np.tile(GT_BOX, (30, 1))
    boxes = gt.copy()
    boxes[11], boxes[12], boxes[13:17] = HALF, AWAY, np.nan
    return ResetRun(boxes, gt, (0, 17), (12,))


def test_accuracy_leaves_out_burn_in_and_failure_frames():
    # counted: frames 10, 11 (after the first burn-in 0-9), 27, 28, 29 (after 17-26); not 12 (failure)
    assert sequence_scores(one_failure()) == {"accuracy": pytest.approx((1 + 0.5 + 3) / 5), "failures": 1,
                                              "frames": 5}


def test_eao_of_a_padded_and_a_last_fragment():
    run = one_failure()
    (first, padded), (last, more) = fragments(run)
    assert padded and len(first) == 13 and not more and len(last) == 13
    # Φ(Ns): the mean of the Ns - 1 frames after each start; the first fragment is 0 from frame 12
    # on and counts at any length, the last (13 frames) only up to Ns = 13
    phi = {12: (10.5 / 11 + 1) / 2, 13: (10.5 / 12 + 1) / 2, 14: 10.5 / 13, 40: 10.5 / 39}
    np.testing.assert_allclose(expected_overlaps([run], list(phi)), list(phi.values()))
    assert eao([run], (12, 14)) == pytest.approx(np.mean([phi[12], phi[13], phi[14]]))


def test_a_failure_too_late_to_restart_leaves_its_fragment_unpadded():
    # the VOT2016 toolkit pads a fragment only up to the next start: a failure on frame 27 of 30
    # (restart at 32, past the end) leaves the run's only fragment as long as the sequence
    gt = np.tile(GT_BOX, (30, 1))
    boxes = gt.copy()
    boxes[27], boxes[28:] = AWAY, np.nan
    run = ResetRun(boxes, gt, (0,), (27,))
    assert [(len(o), padded) for o, padded in fragments(run)] == [(30, False)]
    phi = expected_overlaps([run], [30, 31])
    assert phi[0] == pytest.approx(26 / 29) and np.isnan(phi[1])


def test_fragments_of_several_sequences_weigh_alike():
    clean = ResetRun(np.tile(GT_BOX, (20, 1)), np.tile(GT_BOX, (20, 1)), (0,), ())
    early = np.tile(GT_BOX, (20, 1))
    early[3:] = np.nan
    early[2] = AWAY
    failed = ResetRun(early, np.tile(GT_BOX, (20, 1)), (0,), (2,))  # failed on 2 and never started again
    # lengths 2..20: clean gives 1; the failed one has frame 1 at overlap 1 then zeros: 1 / (Ns - 1)
    ns = np.arange(2, 21)
    expected = (1 + 1 / (ns - 1)) / 2
    expected[ns > 20] = np.nan
    np.testing.assert_allclose(expected_overlaps([clean, failed], ns), expected)


def test_interval_holds_half_the_length_density_around_its_mode():
    lengths = [120, 150, 160, 170, 200, 260, 400, 90]
    low, high = eao_interval(lengths)
    density = stats.gaussian_kde(np.asarray(lengths, float))(np.arange(1, 401))
    density /= density.sum()
    assert low <= np.argmax(density) + 1 <= high
    assert density[low - 1:high].sum() >= 0.5
    # the last step was needed: without the end it added, the mass was short of half
    assert min(density[low:high].sum(), density[low - 1:high - 1].sum()) < 0.5
    assert eao_interval([60, 60, 60]) == (60, 60) and eao_interval([75]) == (75, 75)


def test_score_resets_rows_and_statistics():
    good = one_failure()
    clean = ResetRun(np.tile(GT_BOX, (30, 1)), np.tile(GT_BOX, (30, 1)), (0,), ())
    results = {"a": {"s1": good, "s2": clean}, "b": {"s1": clean, "s2": clean}}
    scores = score_resets(results, {"s1": 30, "s2": 30, "s3": 40}, interval=(12, 14))
    assert scores["interval"] == [12, 14] and scores["left_out"] == {"s3": ["a", "b"]}
    rows = {r["tracker"]: r for r in scores["overall"]}
    assert [r["tracker"] for r in scores["overall"]] == ["b", "a"]  # best EAO first
    assert rows["a"]["failures"] == 1 and rows["b"]["failures"] == 0 and rows["a"]["sequences"] == 2
    # frames pooled: 5 counted in s1 (sum 4.5), 20 in s2 (after the burn-in of its one start)
    assert rows["a"]["accuracy"] == pytest.approx((4.5 + 20) / 25) == pooled_accuracy([good, clean])
    assert rows["b"]["eao"] == 1.0 and rows["a"]["eao"] < 1.0
    assert rows["a"]["eao_ci_low"] <= rows["a"]["eao"] <= rows["a"]["eao_ci_high"]
    differences = scores["statistics"].differences["a"]
    assert differences["failures"].mean == 0.5 and differences["accuracy"].mean == pytest.approx(-0.05)
    from_a = score_resets(results, {"s1": 30, "s2": 30}, interval=(12, 14), baseline="a")["statistics"]
    assert from_a.baseline == "a" and from_a.differences["b"]["failures"].mean == -0.5
    with pytest.raises(DatasetError, match="--baseline 'c': no such tracker in this report; its trackers are 'b', 'a'"):
        score_resets(results, {"s1": 30, "s2": 30}, interval=(12, 14), baseline="c")


def test_the_eao_interval_leaves_out_resamples_without_an_eao():
    # no failures: a 20-frame sequence has no fragment reaching 25, so a resample of it alone has no EAO
    short = ResetRun(np.tile(GT_BOX, (20, 1)), np.tile(GT_BOX, (20, 1)), (0,), ())
    long = ResetRun(np.tile(GT_BOX, (40, 1)), np.tile(GT_BOX, (40, 1)), (0,), ())
    scores = score_resets({"t": {"s": short, "l": long}}, {"s": 20, "l": 40}, interval=(25, 30))
    row = scores["overall"][0]
    assert row["eao"] == 1.0 and row["eao_ci_low"] == row["eao_ci_high"] == 1.0


def test_one_frame_sequences_have_no_eao():
    """Nothing is tracked in a one-frame sequence (frame 1 is the start): the interval is Ns = 1
    alone, whose Φ the VOT2016 toolkit sets to 1 by definition (estimate_expected_overlap.m, "do not
    calculate for Ns == 1"), and the VOT Python toolkit to 0; neither is a tracker's overlap."""
    gt = np.array([GT_BOX])
    nothing = ResetRun(np.full((1, 4), np.nan), gt, (0,), ())
    scores = score_resets({"t": {"s": nothing, "r": nothing}}, {"s": 1, "r": 1})
    assert scores["interval"] == [1, 1]
    row = scores["overall"][0]
    assert np.isnan(row["eao"]) and np.isnan(row["eao_ci_low"]) and np.isnan(row["eao_ci_high"])
    assert expected_overlaps([nothing], [1])[0] == 1.0  # the toolkit's Φ(1), kept for longer intervals
    assert eao([one_failure()], (1, 2)) == pytest.approx((1 + 1) / 2)


def test_vot2016_s_accuracy_is_unbounded_and_its_eao_inside_the_image():
    """The VOT2016 toolkit's accuracy ranking passes no image to its overlap, its EAO the image's
    [0, W - 1] x [0, H - 1]: a box and ground truth [5, 0, 10, 10] in a 12 px wide image overlap
    by 1 in the accuracy and by the 7 x 11 pixels of columns 5..11 over 11 x 11 in the EAO."""
    box = [5.0, 0.0, 10.0, 10.0]
    run = reset_scores.ResetRun(np.tile(box, (3, 1)), np.tile([0.0, 0.0, 10.0, 10.0], (3, 1)), (0,), (), (12, 20))
    boxes = np.tile(box, (3, 1))
    same = reset_scores.ResetRun(boxes, boxes.copy(), (0,), (), (12, 20), "vot2016")
    np.testing.assert_allclose(same.accuracy_overlaps, 1.0)
    np.testing.assert_allclose(same.overlaps, 1.0)
    np.testing.assert_allclose(run.accuracy_overlaps, 66 / 176)  # columns 0..10 and 5..15, 11 rows, unbounded
    np.testing.assert_allclose(run.overlaps, 66 / 132)  # 0..10 and 5..11 in columns 0..11
