"""The three scoring protocols against cases worked out by hand from each toolkit's code, an
independent frame-by-frame re-implementation of the OTB toolkit's calcSeqErrRobust, and the
report on the authors' result files (skipped without ../shared/data).

Boxes in this file are written 1-based, as the result and annotation files hold them; the
per-frame rules are called with them directly, and ``score_sequence`` (which takes dcfkit's
0-based boxes) gets them minus 1 in x and y.
"""
from __future__ import annotations

import json
import math
import shutil

import numpy as np
import pytest

from dcfkit import cli
from dcfkit.analysis import metrics
from dcfkit.datasets import read_boxes
from dcfkit.protocols import PROTOCOLS, get_protocol

NAN = [math.nan] * 4
SQ13 = math.sqrt(13)

# one sequence with every awkward case (1-based x, y, w, h)
GT = np.array([
    [11, 11, 10, 10],   # 1
    [11, 11, 10, 10],   # 2
    NAN,                # 3: target out of view (a UAV123 NaN row)
    [11, 11, 0, 10],    # 4: zero-width ground truth
    [0, 11, 10, 10],    # 5: ground truth starting at x = 0
    [11, 11, 10, 10],   # 6
    [11, 11, 10, 10],   # 7
    [11, 11, 10, 10],   # 8
])
PRED = np.array([
    NAN,                 # 1: failed on the first frame
    NAN,                 # 2: failed on the second frame
    [14, 15, 10, 10],    # 3
    NAN,                 # 4
    [21, 11, 10, 10],    # 5
    [14, 15, 0, 10],     # 6: zero-width prediction
    [math.nan, 12, 10, 10],  # 7: only x is NaN
    [13, 14, 10, 10],    # 8: an ordinary box, centre offset (2, 3)
])


def zero_based(boxes):
    return np.asarray(boxes, dtype=float) - [1, 1, 0, 0]


def frames(protocol, pred, gt):
    return PROTOCOLS[protocol].frames(np.asarray(pred, float), np.asarray(gt, float))


def test_registry():
    assert list(PROTOCOLS) == ["otb", "pysot", "got10k", "lasot"]
    assert get_protocol("OTB") is PROTOCOLS["otb"] and get_protocol(PROTOCOLS["pysot"]) is PROTOCOLS["pysot"]
    with pytest.raises(ValueError, match="unknown scoring protocol 'vot'; one of: otb, pysot, got10k"):
        get_protocol("vot")


# --------------------------------------------------------------------------- otb


def test_otb_by_hand():
    """calcSeqErrRobust.m: frame by frame.

    1: replaced by the ground truth afterwards (rectMat(1,:) = rect_anno(1,:)): IoU 1, error 0.
    2: all NaN, ground truth without NaN: replaced by results.res(1,:), the *file's* frame-1
       box, which is NaN (the ground-truth copy happens after the loop): NaN, NaN.
    3, 4, 5: ground truth not all > 0 (NaN; w = 0; x = 0): overlap -1, error -1 (4 is still
       replaced by 3's box first, which changes nothing).
    6: w = 0: replaced by frame 5's box (21, 11, 10, 10). Centre 21 + 4.5 = 25.5 against
       15.5: error 10; calcRectInt width min(30, 20) - max(21, 11) + 1 = 0: IoU 0.
    7: only x NaN: MATLAB's `if` needs all four elements of (isnan(r) | r(3)<=0 | r(4)<=0)
       true, so it is kept. Centre x NaN: error NaN. calcRectInt's min/max ignore NaN:
       width min(NaN, 20) - max(NaN, 11) + 1 = 10, height min(21, 20) - max(12, 11) + 1 = 9,
       areas 100 + 100 - 90: IoU 90/110.
    8: width min(22, 20) - max(13, 11) + 1 = 8, height 20 - 14 + 1 = 7: IoU 56/144; error sqrt(13).
    """
    f = frames("otb", PRED, GT)
    np.testing.assert_allclose(f.overlap, [1, np.nan, -1, -1, -1, 0, 90 / 110, 56 / 144])
    np.testing.assert_allclose(f.error, [0, np.nan, -1, -1, -1, 10, np.nan, SQ13])
    assert f.counted.all()
    s = metrics.score_sequence(zero_based(PRED), zero_based(GT), protocol="otb")
    assert s["frames"] == 8  # every frame in the denominator
    # error <= 20 px: frames 1, 3, 4, 5 (-1), 6 (10), 8 (3.6); NaN (2, 7) fails
    assert s["precision"] == pytest.approx(6 / 8) and s["precision_curve"][0] == pytest.approx(4 / 8)
    # overlap > t: 3 frames (1, .818, .389) for t <= 0.35 (8 thresholds), 2 for 0.4..0.8 (9),
    # 1 for 0.85..0.95 (3), 0 at 1: (8*3 + 9*2 + 3*1) / (8 frames * 21 thresholds)
    assert s["success_curve"][0] == pytest.approx(3 / 8) and s["success_curve"][8] == pytest.approx(2 / 8)
    assert s["success_curve"][16] == pytest.approx(2 / 8) and s["success_curve"][17] == pytest.approx(1 / 8)
    assert s["auc"] == pytest.approx(45 / 168)


def test_otb_never_repairs_a_prediction_in_a_frame_whose_ground_truth_has_a_nan():
    """Frame 2's empty box is kept (its ground truth is NaN, so `& ~isnan(r_anno)` fails) and
    frame 3's NaN box is replaced by it: centre 11 + (0-1)/2 = 10.5 against 15.5 (error 5),
    calcRectInt width min(10, 20) - max(11, 11) + 1 = 0 (IoU 0). Had frame 2 been repaired
    from frame 1, frame 3 would score IoU 1, error 0."""
    gt = [[11, 11, 10, 10], NAN, [11, 11, 10, 10]]
    pred = [[11, 11, 10, 10], [11, 11, 0, 10], NAN]
    f = frames("otb", pred, gt)
    np.testing.assert_allclose(f.overlap, [1, -1, 0])
    np.testing.assert_allclose(f.error, [0, -1, 5])


def test_otb_thresholds_and_perfect_tracker():
    p = PROTOCOLS["otb"]
    assert len(p.success_thresholds) == 21 and p.success_thresholds[10] == 0.5 and p.success_thresholds[-1] == 1
    np.testing.assert_array_equal(p.precision_thresholds, np.arange(51))
    gt = zero_based([[11, 11, 10, 10], [11, 11, 20, 10], [31, 11, 10, 10]])
    # IoU exactly 0.5 (frame 2: 100 / 200) fails t = 0.5 (strict >) and passes 0.45;
    # an error of exactly 20 px (frame 3: centres 20 px apart) passes 20 px (<=)
    s = metrics.score_sequence(zero_based([[11, 11, 10, 10], [11, 11, 10, 10], [11, 11, 10, 10]]), gt)
    assert s["success_curve"][9] == pytest.approx(2 / 3) and s["success_curve"][10] == pytest.approx(1 / 3)
    assert s["precision_curve"][20] == 1 and s["precision_curve"][19] == pytest.approx(2 / 3)
    assert metrics.score_sequence(gt, gt)["auc"] == pytest.approx(20 / 21)  # IoU > 1 never holds


def test_otb_average_leaves_out_all_zero_curves_but_not_missing_results():
    """plotDrawSave keeps the rows with sum(aa, 2) > eps. Sequence B's ground truth is empty
    throughout: every overlap is -1 (success curve all 0: left out of the success mean) and
    every error -1 (precision curve all 1: kept). A missing result (C) stays a total failure."""
    gt = zero_based([[11, 11, 10, 10]] * 2)
    a = metrics.score_sequence(gt, gt)                                        # AUC 20/21, precision 1
    b = metrics.score_sequence(zero_based([[50, 50, 10, 10]] * 2), zero_based([[11, 11, 0, 10]] * 2))
    c = metrics.score_sequence(np.empty((0, 4)), gt)                          # no result: all fail
    assert b["success_curve"].sum() == 0 and b["precision"] == 1 and c["auc"] == 0 and c["given"] == 0
    avg = metrics.average([a, b])
    assert avg["auc"] == pytest.approx(20 / 21) and avg["precision"] == 1
    avg = metrics.average([a, c])
    assert avg["auc"] == pytest.approx(10 / 21) and avg["precision"] == pytest.approx(0.5)
    pysot = [metrics.score_sequence(x, y, protocol="pysot") for x, y in
             ((gt, gt), (zero_based([[50, 50, 10, 10]] * 2), zero_based([[11, 11, 0, 10]] * 2)))]
    assert metrics.average(pysot, protocol="pysot")["auc"] == pytest.approx(10 / 21)  # pysot keeps B


# --------------------------------------------------------------------------- pysot


def test_pysot_by_hand():
    """ope_benchmark.py / statistics.py: no repair, first frame as the file has it.

    overlap: -1 unless gt w > 0 and h > 0; else continuous IoU clipped to [0, 1] (NaN stays NaN).
    error: -1 unless the gt centre x + (w-1)/2, y + (h-1)/2 is > 0 on both axes.
    1, 2: NaN prediction, gt in view: NaN, NaN.
    3: gt NaN: -1, -1.
    4: gt w = 0: overlap -1; centre (10.5, 15.5) > 0 so error is scored: NaN.
    5: gt x = 0 is scored: [21, 31) and [0, 10) do not overlap: 0; centres 25.5 and 4.5: error 21.
    6: w = 0: intersection width min(14, 21) - max(14, 11) = 0: IoU 0; centre (13.5, 19.5)
       against (15.5, 15.5): error sqrt(4 + 16).
    7: x NaN: np.maximum propagates NaN: NaN, NaN.
    8: [13, 23) x [14, 24) and [11, 21) x [11, 21): 8 x 7 = 56, IoU 56/144; error sqrt(13).
    """
    f = frames("pysot", PRED, GT)
    np.testing.assert_allclose(f.overlap, [np.nan, np.nan, -1, -1, 0, 0, np.nan, 56 / 144])
    np.testing.assert_allclose(f.error, [np.nan, np.nan, -1, np.nan, 21, math.sqrt(20), np.nan, SQ13])
    s = metrics.score_sequence(zero_based(PRED), zero_based(GT), protocol="pysot")
    assert s["frames"] == 8
    # error <= 20: frames 3 (-1), 6 (4.5), 8 (3.6); <= 50 adds frame 5 (21)
    assert s["precision"] == pytest.approx(3 / 8) and s["precision_curve"][50] == pytest.approx(4 / 8)
    # overlap > t: only frame 8 (.389), for t = 0 .. 0.35 (8 thresholds)
    assert s["auc"] == pytest.approx(8 / (8 * 21))


def test_pysot_empty_ground_truth():
    """(0, 0, 0, 0): centre (-0.5, -0.5) is not > 0: error -1 (within every threshold) and
    overlap -1. An empty box away from the origin, (20, 20, 0, 0), has centre (19.5, 19.5):
    its error is scored (the far prediction fails it) while the OTB toolkit gives -1."""
    gt = [[11, 11, 10, 10], [0, 0, 0, 0], [20, 20, 0, 0]]
    pred = [[11, 11, 10, 10], [100, 100, 10, 10], [100, 100, 10, 10]]
    f = frames("pysot", pred, gt)
    np.testing.assert_allclose(f.overlap, [1, -1, -1])
    np.testing.assert_allclose(f.error[:2], [0, -1])
    assert f.error[2] == pytest.approx(math.hypot(100 + 4.5 - 19.5, 100 + 4.5 - 19.5))
    np.testing.assert_allclose(frames("otb", pred, gt).error, [0, -1, -1])


def test_pysot_thresholds():
    p = PROTOCOLS["pysot"]
    assert len(p.success_thresholds) == 21 and p.success_thresholds[-1] == 1.0
    assert p.norm_precision_thresholds[20] == 0.2 and p.weighting == "sequence" and not p.drop_zero_curves


# --------------------------------------------------------------------------- got10k


def test_got10k_by_hand():
    """experiments/got10k.py: frame 1 and NaN rows are out of the denominator, the rest are
    scored with rect_iou (continuous, inter / (union + eps), clipped to [0, 1]).

    Counted: 2, 4, 5, 6, 7, 8. IoU: 2 NaN prediction (dcfkit: 0), 4 NaN (0), 5 no overlap (0),
    6 empty prediction (0), 7 x NaN (0), 8 56/144. AO = (56/144) / 6. Success over
    linspace(0, 1, 101): frame 8 passes t = 0.00 .. 0.38 (39 thresholds). Errors: 2 NaN,
    4 NaN, 5 21, 6 sqrt(20), 7 NaN, 8 sqrt(13): 2 of 6 within 20 px.
    """
    f = frames("got10k", PRED, GT)
    assert f.counted.tolist() == [False, True, False, True, True, True, True, True]
    np.testing.assert_allclose(f.overlap[f.counted], [0, 0, 0, 0, 0, 56 / 144])
    s = metrics.score_sequence(zero_based(PRED), zero_based(GT), protocol="got10k")
    assert s["frames"] == 6
    assert s["ao"] == pytest.approx(56 / 144 / 6) and s["sr50"] == 0 and s["sr75"] == 0
    assert s["auc"] == pytest.approx(39 / (6 * 101)) and s["precision"] == pytest.approx(2 / 6)


def test_got10k_overlap_scores_and_pooling():
    """SR counts IoU > 0.5 and > 0.75 (strict). Frames 2, 4, 5 (3 is NaN, 1 is not scored):
    IoU 100/200 = 0.5, 1, 80/120: AO (0.5 + 1 + 2/3) / 3, SR@0.5 2/3, SR@0.75 1/3; success
    curve: 0.5 passes t = 0 .. 0.49 (50), 1 passes 100, 2/3 passes 0 .. 0.66 (67)."""
    gt = [[1, 1, 10, 10]] * 5
    gt[2] = NAN
    pred = [[90, 90, 5, 5], [1, 1, 20, 10], [1, 1, 10, 10], [1, 1, 10, 10], [3, 1, 10, 10]]
    a = metrics.score_sequence(zero_based(pred), zero_based(gt), protocol="got10k")
    assert a["frames"] == 3
    assert a["ao"] == pytest.approx((0.5 + 1 + 2 / 3) / 3)
    assert a["sr50"] == pytest.approx(2 / 3) and a["sr75"] == pytest.approx(1 / 3)
    assert a["auc"] == pytest.approx(217 / 303)
    # a second sequence, one scored frame with IoU 0: frames are pooled (np.concatenate)
    b = metrics.score_sequence(zero_based([[1, 1, 10, 10], [50, 50, 10, 10]]),
                               zero_based([[1, 1, 10, 10]] * 2), protocol="got10k")
    avg = metrics.average([a, b], protocol="got10k")
    assert avg["ao"] == pytest.approx((0.5 + 1 + 2 / 3 + 0) / 4) and avg["sr50"] == pytest.approx(2 / 4)
    assert metrics.average([a, b], "sequence", "got10k")["ao"] == pytest.approx(((0.5 + 1 + 2 / 3) / 3) / 2)


def test_average_refuses_scores_of_another_protocol():
    gt = zero_based([[1, 1, 10, 10]] * 2)
    with pytest.raises(ValueError, match="averaging 'otb' scores with scores of protocol pysot"):
        metrics.average([metrics.score_sequence(gt, gt, protocol="pysot")])


def test_missing_rows_fail_in_every_protocol():
    """A result two rows short: the rows it lacks fail every threshold, with no repair from
    the last box (otb) and whatever the ground truth (frame 4 is out of view)."""
    gt = zero_based([[11, 11, 10, 10]] * 3 + [NAN])
    for name in PROTOCOLS:
        s = metrics.score_sequence(gt[:2], gt, protocol=name)
        assert s["precision_curve"][-1] == pytest.approx({"otb": 2 / 4, "pysot": 2 / 4, "got10k": 1 / 2, "lasot": 2 / 4}[name])


# --------------------------------------------------------------------------- an independent OTB loop


def matlab_min(a, b):
    """MATLAB's min of two scalars: a NaN loses to a number."""
    return b if math.isnan(a) else a if math.isnan(b) else min(a, b)


def matlab_max(a, b):
    return b if math.isnan(a) else a if math.isnan(b) else max(a, b)


def calc_seq_err_robust(res, anno):
    """calcSeqErrRobust.m with calcRectInt.m, frame by frame in plain Python, written for this
    test from the MATLAB source. ``res`` and ``anno`` are lists of 1-based [x, y, w, h]; returns
    (overlaps, centre errors), -1 where the ground truth is not all > 0."""
    res = [list(r) for r in res]
    for i in range(1, len(res)):
        r, g = res[i], anno[i]
        # if (isnan(r) | r(3)<=0 | r(4)<=0) & (~isnan(r_anno)): an `if` on a 1x4 vector needs all four true
        if all((math.isnan(r[k]) or r[2] <= 0 or r[3] <= 0) and not math.isnan(g[k]) for k in range(4)):
            res[i] = list(res[i - 1])
    res[0] = list(anno[0])  # rectMat(1,:) = rect_anno(1,:)
    overlaps, errors = [], []
    for r, g in zip(res, anno):
        if not all(v > 0 for v in g):  # idx = sum(rect_anno > 0, 2) == 4 (NaN > 0 is false)
            overlaps.append(-1.0)
            errors.append(-1.0)
            continue
        dx = (r[0] + (r[2] - 1) / 2) - (g[0] + (g[2] - 1) / 2)
        dy = (r[1] + (r[3] - 1) / 2) - (g[1] + (g[3] - 1) / 2)
        errors.append(math.sqrt(dx * dx + dy * dy))
        iw = matlab_max(0, matlab_min(r[0] + r[2] - 1, g[0] + g[2] - 1) - matlab_max(r[0], g[0]) + 1)
        ih = matlab_max(0, matlab_min(r[1] + r[3] - 1, g[1] + g[3] - 1) - matlab_max(r[1], g[1]) + 1)
        inter = iw * ih
        union = r[2] * r[3] + g[2] * g[3] - inter
        overlaps.append(inter / union if union != 0 else (math.nan if inter == 0 else math.copysign(math.inf, inter)))
    return overlaps, errors


def otb_curves(res, anno):
    """genPerfMat.m for one sequence: success over 0:0.05:1 (overlap >), precision over 0:50 (error <=)."""
    overlaps, errors = calc_seq_err_robust(res, anno)
    n = len(anno)
    success = [sum(o > k * 0.05 for o in overlaps) / n for k in range(21)]
    precision = [sum(e <= t for e in errors) / n for t in range(51)]
    return success, precision


def otb_mean(curves):
    """plotDrawSave.m: rows with sum > eps, averaged."""
    kept = [c for c in curves if sum(c) > np.finfo(float).eps]
    return [sum(c[i] for c in kept) / len(kept) for i in range(len(kept[0]))]


@pytest.mark.parametrize("seed", range(8))
def test_otb_against_the_independent_loop(seed):
    rng = np.random.default_rng(seed)
    n = 120
    gt = np.column_stack([rng.uniform(-5, 100, (n, 2)), rng.uniform(1, 60, (n, 2))])
    pred = np.round(gt + rng.normal(0, [8, 8, 6, 6], (n, 4)), 1)  # some exact ties at thresholds
    gt[rng.choice(n, 12, replace=False)] = np.nan
    gt[rng.choice(n, 4, replace=False), 2] = 0
    gt[rng.choice(n, 3, replace=False), 3] = -4
    pred[rng.choice(n, 12, replace=False)] = np.nan
    pred[rng.choice(n, 6, replace=False), 0] = np.nan  # partly NaN
    pred[rng.choice(n, 6, replace=False), 3] = 0
    pred[rng.choice(n, 4, replace=False), 2] = -3
    pred[:2] = np.nan  # failures on frames 1 and 2
    overlaps, errors = calc_seq_err_robust(pred.tolist(), gt.tolist())
    f = frames("otb", pred, gt)
    np.testing.assert_allclose(f.overlap, overlaps, rtol=1e-12)
    np.testing.assert_allclose(f.error, errors, rtol=1e-12)
    success, precision = otb_curves(pred.tolist(), gt.tolist())
    s = metrics.score_sequence(zero_based(pred), zero_based(gt))
    np.testing.assert_allclose(s["success_curve"], success)
    np.testing.assert_allclose(s["precision_curve"], precision)


# --------------------------------------------------------------------------- an independent LaSOT loop


def lasot_curves(res, anno, absent):
    """calc_seq_err_robust.m and eval_tracker.m of the LaSOT toolkit for one sequence, frame by
    frame in plain Python, written for this test from the MATLAB source: the toolkit's inputs are
    the annotation (numbers in every frame) and the ``absent`` flags (annos/absent/<seq>.txt)."""
    res = [list(r) for r in res]
    for i in range(1, len(res)):
        r, g = res[i], anno[i]
        # if (sum(isnan(r)) | ~isreal(r) | r(3)<=0 | r(4)<=0) & (~isnan(r_anno)): a scalar & a 1x4 vector
        failed = any(math.isnan(v) for v in r) or r[2] <= 0 or r[3] <= 0
        if failed and not any(math.isnan(v) for v in g):
            res[i] = list(res[i - 1])
    res[0] = list(anno[0])
    kept = [i for i in range(len(anno)) if not absent[i]]  # rect_mat(absent_idx, :) = []
    overlaps, errors = [], []
    for r, g in ((res[i], anno[i]) for i in kept):
        dx = (r[0] + (r[2] - 1) / 2) - (g[0] + (g[2] - 1) / 2)
        dy = (r[1] + (r[3] - 1) / 2) - (g[1] + (g[3] - 1) / 2)
        if not all(v > 0 for v in g):
            overlaps.append(-1.0)
            errors.append(-1.0)
            continue
        errors.append(math.sqrt(dx * dx + dy * dy))
        iw = matlab_max(0, matlab_min(r[0] + r[2] - 1, g[0] + g[2] - 1) - matlab_max(r[0], g[0]) + 1)
        ih = matlab_max(0, matlab_min(r[1] + r[3] - 1, g[1] + g[3] - 1) - matlab_max(r[1], g[1]) + 1)
        overlaps.append(iw * ih / (r[2] * r[3] + g[2] * g[3] - iw * ih))
    n = len(anno)  # len_all: absent frames stay in the denominator
    success = [sum(o > k * 0.05 for o in overlaps) / n for k in range(21)]
    precision = [sum(e <= t for e in errors) / n for t in range(51)]
    return success, precision


@pytest.mark.parametrize("seed", range(6))
def test_lasot_against_the_independent_loop(seed):
    rng = np.random.default_rng(100 + seed)
    n = 150
    gt = np.column_stack([rng.uniform(1, 100, (n, 2)), rng.uniform(1, 60, (n, 2))]).round(0)
    absent = np.zeros(n, bool)
    absent[rng.choice(np.arange(1, n), 25, replace=False)] = True
    gt[rng.choice(n, 5, replace=False), :2] = 0  # the toolkit's out-of-view boxes outside the absent flags
    gt[absent[:, None] & (rng.random((n, 1)) < 0.5)[:, [0, 0, 0, 0]]] = 0  # LaSOT writes 0,0,0,0 in some absent frames
    pred = np.round(gt + rng.normal(0, [8, 8, 6, 6], (n, 4)), 1)
    pred[rng.choice(n, 10, replace=False)] = np.nan
    pred[rng.choice(n, 10, replace=False), 1] = np.nan  # partly NaN: LaSOT repairs it, OTB keeps it
    pred[rng.choice(n, 5, replace=False), 3] = 0
    pred[absent & (rng.random(n) < 0.3)] = np.nan  # failures in absent frames are repaired too
    success, precision = lasot_curves(pred.tolist(), gt.tolist(), absent.tolist())
    ours = gt.copy()
    ours[absent] = np.nan  # what dcfkit's LaSOT loader makes of the absent flags
    s = metrics.score_sequence(zero_based(pred), zero_based(ours), protocol="lasot")
    np.testing.assert_allclose(s["success_curve"], success)
    np.testing.assert_allclose(s["precision_curve"], precision)
    otb = metrics.score_sequence(zero_based(pred), zero_based(ours), protocol="otb")
    assert otb["precision"] > s["precision"]  # otb lets absent frames pass every precision threshold


def test_lasot_absent_frames_fail_both_curves_by_hand():
    """Four frames, frame 3 absent, and a box with one NaN in frame 4: LaSOT repairs that box
    from frame 3's (which sits on frame 4's ground truth) and fails frame 3 on every threshold;
    otb keeps the NaN box (its centre fails, MATLAB's min/max give it an overlap of 1) and lets
    the absent frame pass precision. Both score 3 of 4 frames, different ones."""
    gt = [[11, 11, 10, 10], [12, 11, 10, 10], NAN, [14, 11, 10, 10]]
    pred = [[11, 11, 10, 10], [12, 11, 10, 10], [14, 11, 10, 10], [math.nan, 11, 10, 10]]
    lasot = frames("lasot", np.array(pred, float), np.array(gt, float))
    otb = frames("otb", np.array(pred, float), np.array(gt, float))
    assert lasot.overlap.tolist() == [1, 1, -1, 1] and lasot.error.tolist() == [0, 0, math.inf, 0]
    assert otb.overlap.tolist() == [1, 1, -1, 1] and otb.error[:3].tolist() == [0, 0, -1] and math.isnan(otb.error[3])
    for name in ("lasot", "otb"):
        s = metrics.score_sequence(zero_based(pred), zero_based(gt), protocol=name)
        assert s["precision"] == 3 / 4 and s["success_curve"][0] == 3 / 4 and s["frames"] == 4


# --------------------------------------------------------------------------- the authors' results


NAN_ROWS = range(120, 151)  # boat1 frames 121-151 made out of view in the test's copy


@pytest.fixture
def uav_root_with_nan_rows(shared_data, tmp_path):
    """A UAV123@10fps root whose boat1 annotation has NaN rows: none of the six development
    annotations has any (grep -c NaN: 0). The images are the shared ones, through a link."""
    root = tmp_path / "UAV123_10fps"
    anno = root / "anno" / "UAV123_10fps"
    anno.mkdir(parents=True)
    (root / "data_seq").symlink_to(shared_data / "UAV123_10fps" / "data_seq", target_is_directory=True)
    for f in (shared_data / "UAV123_10fps" / "anno" / "UAV123_10fps").glob("*.txt"):
        shutil.copyfile(f, anno / f.name)
    lines = (anno / "boat1.txt").read_text().splitlines()
    for i in NAN_ROWS:
        lines[i] = "NaN,NaN,NaN,NaN"
    (anno / "boat1.txt").write_text("\n".join(lines) + "\n")
    return root


def test_report_otb_matches_calc_seq_err_robust_on_the_authors_results(uav_root_with_nan_rows, shared_data, tmp_path):
    refs = shared_data / "reference_results"
    trackers = ["BACF/UAV123_10fps", "DR2Track/UAV123_10fps"]
    assert cli.main(["report", str(refs), "--root", str(uav_root_with_nan_rows), "--dataset", "uav123_10fps",
                     "--trackers", ",".join(trackers), "--report-dir", str(tmp_path / "report"),
                     "--protocol", "otb", "--format", "csv"]) == 0
    data = json.loads((tmp_path / "report" / "report.json").read_text())
    assert data["protocol"]["name"] == "otb"
    overall = {r["tracker"]: r for r in data["overall"]}
    per_sequence = {(r["tracker"], r["sequence"]): r for r in data["per_sequence"]}
    anno_dir = uav_root_with_nan_rows / "anno" / "UAV123_10fps"
    for tracker in trackers:
        successes, precisions = [], []
        for anno_file in sorted(anno_dir.glob("*.txt")):
            anno = [[float(v) for v in line.split(",")] for line in anno_file.read_text().splitlines()]
            res = [[float(v) for v in line.split(",")] for line in
                   (refs / tracker / anno_file.name).read_text().splitlines()]
            success, precision = otb_curves(res, anno)
            successes.append(success)
            precisions.append(precision)
            row = per_sequence[tracker, anno_file.stem]
            assert row["frames"] == len(anno)  # out-of-view frames stay in the denominator
            assert row["auc"] == pytest.approx(sum(success) / 21, abs=5e-4)
            assert row["precision"] == pytest.approx(precision[20], abs=5e-4)
        assert overall[tracker]["auc"] == pytest.approx(sum(otb_mean(successes)) / 21, abs=5e-4)
        assert overall[tracker]["precision"] == pytest.approx(otb_mean(precisions)[20], abs=5e-4)
    # the NaN rows were scored as the toolkit scores them: in the denominator, never a success
    boat1 = read_boxes(anno_dir / "boat1.txt")
    assert np.isnan(boat1[list(NAN_ROWS)]).all() and len(boat1) == 301
    original = [[float(v) for v in line.split(",")] for line in
                (shared_data / "UAV123_10fps" / "anno" / "UAV123_10fps" / "boat1.txt").read_text().splitlines()]
    res = [[float(v) for v in line.split(",")] for line in (refs / trackers[0] / "boat1.txt").read_text().splitlines()]
    assert per_sequence[trackers[0], "boat1"]["auc"] < sum(otb_curves(res, original)[0]) / 21 - 0.05
