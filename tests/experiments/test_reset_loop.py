"""VOT's reset-based frame loop: failures where the box leaves the ground truth, a fresh
tracker from the ground truth 5 frames later, nothing tracked between."""
from __future__ import annotations

import numpy as np
import pytest

from dcfkit.datasets import Sequence
from dcfkit.experiments.vot import SKIP, valid_box
from dcfkit.experiments.vot import next_start
from dcfkit.experiments.reset import track_with_resets
from dcfkit.experiments.loop import TrackerFailure

N = 30
IMAGE = np.zeros((50, 60, 3), np.uint8)


class Scripted:
    """Returns the ground truth's box, except on the frames in ``lost`` (0-based, of the whole
    sequence), where it returns a box far away; counts the frames it was asked to track."""

    made: list = []

    def __init__(self, gt, lost=(), raise_at=None):
        self.gt, self.lost, self.raise_at = gt, set(lost), raise_at
        Scripted.made.append(self)

    def init(self, image, box):
        self.frame = int(np.flatnonzero((self.gt == box).all(axis=1))[0])
        self.start, self.updates = self.frame, 0

    def update(self, image):
        self.frame += 1
        self.updates += 1
        if self.frame == self.raise_at:
            raise RuntimeError("lost it")
        return [50.0, 40.0, 5.0, 5.0] if self.frame in self.lost else self.gt[self.frame]


def sequence(gt):
    return Sequence("s", tuple(f"{k:04d}.jpg" for k in range(len(gt))), gt, dataset="fake")


def ground_truth():
    return np.column_stack([np.arange(N, dtype=float), np.full(N, 2.0), np.full(N, 8.0), np.full(N, 6.0)])


def run(gt, **script):
    Scripted.made = []
    return track_with_resets(lambda: Scripted(gt, **script), sequence(gt), lambda i: IMAGE)


def test_a_failure_restarts_a_fresh_tracker_five_frames_later():
    gt = ground_truth()
    result = run(gt, lost=[7, 20])
    assert result.failures == [7, 20] and result.starts == [0, 7 + SKIP, 20 + SKIP]
    assert len(Scripted.made) == 3 and [t.start for t in Scripted.made] == result.starts
    tracked = np.isfinite(result.boxes).all(axis=1)
    assert not tracked[8:12].any() and not tracked[21:25].any()  # frames f+1..f+4: not tracked, not read
    assert tracked[:8].all() and tracked[12:21].all() and tracked[25:].all()
    np.testing.assert_array_equal(result.boxes[12], gt[12])  # a restart reports the ground truth
    assert np.isnan(result.times[8:12]).all() and np.isfinite(result.times[tracked]).all()
    assert result.fps == pytest.approx(tracked.sum() / np.nansum(result.times))


def test_a_frame_without_ground_truth_is_never_a_failure_and_restarts_skip_it():
    gt = ground_truth()
    gt[10] = np.nan  # the box far away there overlaps no ground truth: no failure (VOT2016 toolkit)
    gt[12:14] = np.nan  # the restart after a failure on frame 7 waits for a valid box: frame 14
    result = run(gt, lost=[7, 10])
    assert result.failures == [7] and result.starts == [0, 14]
    assert next_start(gt, 12) == 14 and next_start(gt[:13], 12) is None


def test_a_failure_too_late_to_restart_ends_the_run():
    gt = ground_truth()
    result = run(gt, lost=[N - 3])
    assert result.failures == [N - 3] and result.starts == [0]
    assert np.isnan(result.boxes[N - 2:]).all()


def test_an_exception_names_the_frame_of_the_whole_sequence():
    gt = ground_truth()
    with pytest.raises(TrackerFailure, match="frame 16: update raised RuntimeError: lost it") as info:
        run(gt, lost=[7], raise_at=15)
    assert info.value.frame == 16


def test_valid_boxes():
    assert valid_box([0, 0, 1, 1]) and not valid_box([0, 0, -1, 1]) and not valid_box([np.inf, 0, 1, 1])


class Sliver(Scripted):
    """On frame 7, a box 1 px wide over the ground truth's last 0.4 px (a continuous overlap of
    0.4 x 6 / 50.6 > 0, which dcfkit <= 0.9.0 kept tracking)."""

    def update(self, image):
        box = np.array(super().update(image), dtype=float)
        return np.array([box[0] + 7.6, box[1], 1.0, box[3]]) if self.frame == 7 else box


@pytest.mark.parametrize("rule", ["vot2016", "vot-toolkit"])
def test_the_rule_decides_the_failures_and_is_recorded(rule):
    gt = ground_truth()
    found = track_with_resets(lambda: Sliver(gt), sequence(gt), lambda i: IMAGE, rule=rule)
    assert found.failures == [7] and found.starts == [0, 7 + SKIP]
    assert found.record() == {"rule": rule, "starts": [1, 13], "failures": [8]}
