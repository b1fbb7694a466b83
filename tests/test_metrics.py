"""Metrics against hand-computed cases and an independent loop over the OTB formulas."""
from __future__ import annotations

import math

import numpy as np
import pytest

from dcfkit import metrics


def test_iou_hand_cases():
    a = [0, 0, 10, 10]
    pred = [[0, 0, 10, 10], [5, 0, 10, 10], [2, 2, 5, 5], [10, 0, 10, 10], [20, 20, 5, 5],
            [0, 0, 20, 10], [np.nan] * 4, [0, 0, 0, 10], [-5, -5, 10, 10]]
    got = metrics.iou(pred, [a] * len(pred))
    expected = [1.0, 50 / 150, 25 / 100, 0.0, 0.0, 0.5, 0.0, 0.0, 25 / 175]
    np.testing.assert_allclose(got, expected)


def test_centre_error_hand_cases():
    gt = [[0, 0, 10, 10]] * 4
    pred = [[3, 4, 10, 10], [0, 0, 20, 20], [0, 0, 10, 10], [np.nan, 0, 10, 10]]
    np.testing.assert_allclose(metrics.centre_error(pred, gt), [5, math.hypot(5, 5), 0, np.inf])
    # normalized: dx / w, dy / h of the ground truth
    ne = metrics.normalized_centre_error([[3, 4, 10, 20]], [[0, 0, 10, 20]])
    np.testing.assert_allclose(ne, [math.hypot(0.3, 0.2)])


def test_four_frame_sequence_by_hand():
    gt = np.array([[0, 0, 10, 10]] * 4 + [[np.nan] * 4] + [[5, 5, 0, 8]], dtype=float)
    pred = np.array([
        [0, 0, 10, 10],     # frame 0: error 0,  IoU 1
        [3, 4, 10, 10],     # frame 1: error 5,  IoU 6*7/(200-42) = 42/158
        [12, 16, 10, 10],   # frame 2: error 20, IoU 0 (disjoint)
        [np.nan] * 4,       # frame 3: failure -> error inf, IoU 0
        [0, 0, 10, 10],     # frame 4: gt NaN -> not scored
        [0, 0, 10, 10],     # frame 5: gt with zero width -> not scored
    ])
    s = metrics.score_sequence(pred, gt)
    assert s["frames"] == 4
    assert s["precision"] == pytest.approx(3 / 4)  # 0, 5, 20 <= 20 px (inclusive)
    p = s["precision_curve"]
    assert p[0] == pytest.approx(1 / 4) and p[5] == pytest.approx(2 / 4) and p[19] == pytest.approx(2 / 4)
    assert p[50] == pytest.approx(3 / 4)
    sc = s["success_curve"]
    # IoUs 1, 0.2658, 0, 0: > 0 -> 2/4; > 0.25 -> 2/4; > 0.3 -> 1/4; > 1 -> 0
    assert sc[0] == pytest.approx(2 / 4) and sc[5] == pytest.approx(2 / 4)
    assert sc[6] == pytest.approx(1 / 4) and sc[20] == 0
    assert s["auc"] == pytest.approx((6 * 2 + 14 * 1) / 4 / 21)  # 6 points at 2/4, 14 at 1/4
    # without the first frame: errors 5, 20, inf
    s2 = metrics.score_sequence(pred, gt, include_first=False)
    assert s2["frames"] == 3 and s2["precision"] == pytest.approx(2 / 3)


def test_threshold_conventions():
    gt = [[0, 0, 10, 10]]
    # IoU exactly 0.5 fails the 0.5 threshold (strict >) and passes 0.45
    s = metrics.score_sequence([[0, 0, 20, 10]], gt)
    assert s["success_curve"][9] == 1 and s["success_curve"][10] == 0
    # centre error exactly 20 px passes the 20 px threshold (<=)
    s = metrics.score_sequence([[12, 16, 10, 10]], gt)
    assert s["precision"] == 1 and s["precision_curve"][19] == 0
    # a perfect tracker: AUC = 20/21 because IoU > 1 never holds
    assert metrics.score_sequence(gt, gt)["auc"] == pytest.approx(20 / 21)


def test_missing_predictions_are_failures():
    gt = [[0, 0, 10, 10]] * 4
    s = metrics.score_sequence([[0, 0, 10, 10]] * 2, gt)
    assert s["precision"] == 0.5 and s["success_curve"][0] == 0.5
    with pytest.raises(ValueError, match="5 predicted boxes for a sequence of 4"):
        metrics.score_sequence([[0, 0, 10, 10]] * 5, gt)
    empty = metrics.score_sequence(np.empty((0, 4)), [[np.nan] * 4])
    assert empty["frames"] == 0 and math.isnan(empty["auc"])


def test_average_sequence_vs_frame_weighting():
    gt = np.array([[0, 0, 10, 10]] * 4)
    good = metrics.score_sequence(gt[:1], gt[:1])                 # 1 frame, precision 1
    bad = metrics.score_sequence([[100, 100, 10, 10]] * 3, gt[:3])  # 3 frames, precision 0
    none = metrics.score_sequence(np.empty((0, 4)), [[np.nan] * 4])
    assert metrics.average([good, bad, none])["precision"] == pytest.approx(0.5)
    assert metrics.average([good, bad, none], "frame")["precision"] == pytest.approx(0.25)
    assert metrics.average([good, bad])["frames"] == 4
    assert math.isnan(metrics.average([none])["auc"])


# --------------------------------------------------------------------------- reference loop


def reference_scores(pred, gt, include_first=True):
    """The OTB formulas written out frame by frame, independently of dcfkit.metrics."""
    errs, ious, nerrs = [], [], []
    for i, (p, g) in enumerate(zip(pred, gt)):
        if not include_first and i == 0:
            continue
        if any(math.isnan(v) for v in g) or g[2] <= 0 or g[3] <= 0:
            continue
        if any(math.isnan(v) or math.isinf(v) for v in p):
            errs.append(math.inf)
            nerrs.append(math.inf)
            ious.append(0.0)
            continue
        pcx, pcy = p[0] + p[2] / 2, p[1] + p[3] / 2
        gcx, gcy = g[0] + g[2] / 2, g[1] + g[3] / 2
        errs.append(math.sqrt((pcx - gcx) ** 2 + (pcy - gcy) ** 2))
        nerrs.append(math.sqrt(((pcx - gcx) / g[2]) ** 2 + ((pcy - gcy) / g[3]) ** 2))
        if p[2] <= 0 or p[3] <= 0:
            ious.append(0.0)
            continue
        # calcRectInt of the OTB toolkit, with its -1 / +1 pixel convention
        right_p, top_p = p[0] + p[2] - 1, p[1] + p[3] - 1
        right_g, top_g = g[0] + g[2] - 1, g[1] + g[3] - 1
        w = max(0.0, min(right_p, right_g) - max(p[0], g[0]) + 1)
        h = max(0.0, min(top_p, top_g) - max(p[1], g[1]) + 1)
        inter = w * h
        ious.append(inter / (p[2] * p[3] + g[2] * g[3] - inter))
    n = len(errs)
    prec = [sum(e <= t for e in errs) / n for t in range(51)]
    succ = [sum(o > t for o in ious) / n for t in [k * 0.05 for k in range(21)]]
    nprec = [sum(e <= t for e in nerrs) / n for t in [k * 0.01 for k in range(51)]]
    return n, prec, succ, nprec


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("include_first", [True, False])
def test_against_reference_loop(seed, include_first):
    rng = np.random.default_rng(seed)
    n = 200
    gt = np.column_stack([rng.uniform(0, 100, (n, 2)), rng.uniform(1, 60, (n, 2))])
    pred = gt + rng.normal(0, [8, 8, 6, 6], (n, 4))
    pred = np.round(pred, 1)  # some exact ties at thresholds
    gt[rng.choice(n, 15, replace=False)] = np.nan
    gt[rng.choice(n, 5, replace=False), 2] = 0
    gt[rng.choice(n, 3, replace=False), 3] = -4
    pred[rng.choice(n, 15, replace=False)] = np.nan
    pred[rng.choice(n, 8, replace=False), 3] = 0
    pred[rng.choice(n, 4, replace=False), 2] = -3
    pred[:5] = gt[:5]
    frames, prec, succ, nprec = reference_scores(pred.tolist(), gt.tolist(), include_first)
    s = metrics.score_sequence(pred, gt, include_first)
    assert s["frames"] == frames
    np.testing.assert_allclose(s["precision_curve"], prec)
    np.testing.assert_allclose(s["success_curve"], succ)
    np.testing.assert_allclose(s["norm_precision_curve"], nprec)
    assert s["precision"] == pytest.approx(prec[20])
    assert s["auc"] == pytest.approx(sum(succ) / 21)
    assert s["norm_precision"] == pytest.approx(nprec[20])
