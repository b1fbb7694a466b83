"""TRE segment starts and SRE first boxes, against values worked out by hand from
splitSeqTRE.m and shiftInitBB.m (Wu et al., TPAMI 2015)."""
from __future__ import annotations

import dataclasses

import cv2
import numpy as np
import pytest

from dcfkit.datasets import DatasetError, Sequence
from dcfkit.experiments import EXPERIMENTS, Experiment, get_experiment, runs_by_sequence
from dcfkit.experiments.otb import SRE_SHIFTS, sre_box, tre_runs, tre_starts


def frames(folder, n: int, size=(60, 80)) -> tuple:
    """``n`` frame paths in ``folder``, the first written (runs are planned on frame 1's size)."""
    paths = tuple(folder / f"{k:04d}.jpg" for k in range(n))
    cv2.imwrite(str(paths[0]), np.zeros((*size, 3), np.uint8))
    return paths


def test_tre_starts_of_a_100_frame_sequence():
    # frames 1..81 have >= 20 frames to the end: E = 81; starts floor(1 + k 81/19), k = 0..18, then 81
    by_hand = [1, 5, 9, 13, 18, 22, 26, 30, 35, 39, 43, 47, 52, 56, 60, 64, 69, 73, 77, 81]
    assert [s + 1 for s in tre_starts(np.ones((100, 4)))] == by_hand


def test_tre_starts_leave_out_frames_without_valid_ground_truth():
    gt = np.ones((60, 4))
    gt[0] = np.nan  # frame 1 missing
    gt[1, 0] = -1.0  # frame 2: 1-based x = 0, which the toolkit's r(1) <= 0 refuses
    gt[2:4, 2] = 0.0  # frames 3-4: no width
    valid = [i for i in range(60) if i >= 4]  # positions 1.. among the valid frames
    # last valid start with 20 frames left: frame 41 (0-based 40), the 37th valid frame: E = 37
    expected = [valid[(19 + k * 37) // 19 - 1] for k in range(19) if 19 + k * 37 <= 37 * 19] + [40]
    assert tre_starts(gt) == expected
    assert expected[0] == 4 and len(expected) == 20


def test_short_sequences_repeat_starts_as_the_toolkit_does():
    # 25 frames: E = 6, 1:6/19:6 has 16 values (floor: 1,1,1,1,2,2,2,3,3,3,4,4,4,5,5,5), then 6
    assert [s + 1 for s in tre_starts(np.ones((25, 4)))] == [1, 1, 1, 1, 2, 2, 2, 3, 3, 3, 4, 4, 4, 5, 5, 5, 6]
    with pytest.raises(DatasetError, match="too short for TRE"):
        tre_starts(np.ones((19, 4)))


def test_tre_runs_start_at_their_frame_from_its_ground_truth(tmp_path):
    gt = np.column_stack([np.arange(40.0), np.zeros(40), np.full(40, 5.0), np.full(40, 6.0)])
    seq = Sequence("walk", frames(tmp_path, 40), gt, dataset="fake")
    runs = tre_runs(seq)
    starts = tre_starts(gt)
    assert [r.name for r in runs] == [f"walk_{k:03d}" for k in range(1, 21)]
    for run, start in zip(runs, starts):
        assert run.frames[0].name == f"{start:04d}.jpg" and len(run) == 40 - start
        np.testing.assert_array_equal(run.init_box, gt[start])
        np.testing.assert_array_equal(run.ground_truth, gt[start:])


@pytest.mark.parametrize("shift, by_hand", [
    # 1-based box (10, 20, 30, 40): right edge 39, bottom 59, centre (25, 40)
    ("left", (7, 20, 30, 40)), ("right", (13, 20, 30, 40)), ("up", (10, 16, 30, 40)), ("down", (10, 24, 30, 40)),
    ("topLeft", (7, 16, 33, 44)), ("topRight", (10, 16, 33, 44)),  # right 39 + 3 = 42: w = 42 - 10 + 1
    ("bottomLeft", (7, 20, 33, 44)), ("bottomRight", (10, 20, 33, 44)),
    ("scale_8", (13, 24, 24, 32)), ("scale_9", (12, 22, 27, 36)),  # 25 - 13.5 = 11.5 rounds away from 0
    ("scale_11", (9, 18, 33, 44)), ("scale_12", (7, 16, 36, 48)),
])
def test_sre_boxes(shift, by_hand):
    box = np.array([9.0, 19.0, 30.0, 40.0])  # 0-based
    expected = np.array(by_hand, dtype=float) - [1, 1, 0, 0]
    np.testing.assert_array_equal(sre_box(box, shift, (480, 640)), expected)


def test_sre_boxes_stay_inside_the_image():
    # 1-based (2, 2, 20, 10) in a 30 x 21 image (h, w): left moves x to 0 -> 1; right reaches past 21
    np.testing.assert_array_equal(sre_box([1, 1, 20, 10], "left", (30, 21)), [0, 1, 20, 10])
    np.testing.assert_array_equal(sre_box([1, 1, 20, 10], "right", (30, 21)), [3, 1, 18, 10])
    np.testing.assert_array_equal(sre_box([1, 1, 20, 10], "down", (11, 21)), [1, 2, 20, 9])  # bottom 12 > 11
    assert len(SRE_SHIFTS) == 12
    with pytest.raises(ValueError, match="unknown SRE shift"):
        sre_box([1, 1, 2, 2], "diagonal", (10, 10))


def test_experiments_by_name(tmp_path):
    assert list(EXPERIMENTS) == ["ope", "tre", "sre", "reset"]
    assert get_experiment("TRE") is EXPERIMENTS["tre"] and get_experiment(EXPERIMENTS["sre"]) is EXPERIMENTS["sre"]
    with pytest.raises(Exception, match="unknown experiment 'xre'; one of: ope, tre, sre, reset"):
        get_experiment("xre")
    seq = Sequence("a", frames(tmp_path, 30), np.ones((30, 4)))
    assert runs_by_sequence([seq], "ope") == {"a": [seq]}
    assert [len(r) for r in runs_by_sequence([seq], "tre")["a"]][-1] == 20


def test_which_experiments_track_each_run_once():
    """OPE's, TRE's and SRE's runs are each tracked once from their first box and stored with
    nothing of their own: one run where two coincide. The reset experiment restarts; an
    experiment that tracks or records differently, or stores runs under a rule, is not one."""
    assert [name for name, e in EXPERIMENTS.items() if e.tracks_once] == ["ope", "tre", "sre"]
    base = dataclasses.asdict(EXPERIMENTS["ope"])

    class Recording(Experiment):
        def record(self, result):
            return {"mine": 1}

    class Checking(Experiment):
        def stored_elsewise(self, meta):
            return None

    class Tracking(Experiment):
        def track(self, tracker, make_tracker, run, read, tick=None):
            return super().track(tracker, make_tracker, run, read, tick)

    assert Experiment(**base).tracks_once
    assert not any(kind(**base).tracks_once for kind in (Recording, Checking, Tracking))
