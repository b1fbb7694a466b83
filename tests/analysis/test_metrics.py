"""Box geometry, curves and averaging against hand-computed cases (the protocols' rules: test_protocols.py)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from dcfkit.analysis import metrics


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


def test_curves_thresholds_are_strict_for_overlap_and_inclusive_for_error():
    # overlap 0.5 fails t = 0.5 and passes 0.45; error 20 passes t = 20 and fails 19;
    # -1 (out of view in the OTB toolkit) passes every error threshold and no overlap threshold
    sc = metrics.success_curve([0.5, -1.0, np.nan], np.linspace(0, 1, 21))
    assert sc[9] == pytest.approx(1 / 3) and sc[10] == 0 and sc[0] == pytest.approx(1 / 3)
    pc = metrics.precision_curve([20.0, -1.0, np.nan, np.inf], np.arange(51))
    assert pc[20] == pytest.approx(2 / 4) and pc[19] == pytest.approx(1 / 4) and pc[0] == pytest.approx(1 / 4)
    assert np.isnan(metrics.success_curve([], [0.0, 0.5])).all()


def test_missing_predictions_are_failures():
    gt = [[0, 0, 10, 10]] * 4
    s = metrics.score_sequence([[0, 0, 10, 10]] * 2, gt)
    assert s["precision"] == 0.5 and s["success_curve"][0] == 0.5 and s["given"] == 2
    with pytest.raises(ValueError, match="5 predicted boxes for a sequence of 4"):
        metrics.score_sequence([[0, 0, 10, 10]] * 5, gt)
    # got10k counts no frame of a one-frame sequence (the first frame is not scored)
    empty = metrics.score_sequence(np.empty((0, 4)), [[0, 0, 10, 10]], protocol="got10k")
    assert empty["frames"] == 0 and math.isnan(empty["auc"]) and math.isnan(empty["ao"])


def test_average_sequence_vs_frame_weighting():
    gt = np.array([[0, 0, 10, 10]] * 4)
    good = metrics.score_sequence(gt[:1], gt[:1], protocol="pysot")                 # 1 frame, precision 1
    bad = metrics.score_sequence([[100, 100, 10, 10]] * 3, gt[:3], protocol="pysot")  # 3 frames, precision 0
    none = metrics.score_sequence(np.empty((0, 4)), np.empty((0, 4)), protocol="pysot")  # no frame
    assert metrics.average([good, bad, none], protocol="pysot")["precision"] == pytest.approx(0.5)
    assert metrics.average([good, bad, none], "frame", "pysot")["precision"] == pytest.approx(0.25)
    assert metrics.average([good, bad], protocol="pysot")["frames"] == 4
    assert math.isnan(metrics.average([none], protocol="pysot")["auc"])
    with pytest.raises(ValueError, match="weighting must be 'sequence' or 'frame'"):
        metrics.average([good], "pooled", "pysot")
