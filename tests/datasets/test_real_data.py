"""Shipped configs on the real UAV123@10fps development sequences (skipped without ../shared/data).

Precision floors were set from measurement (one-pass, centre error <= 20 px, mean over the six
development sequences, OpenCV 4.14): DR²Track 0.959, STRCF 0.891, BACF 0.978 at the time of
writing (2026-11-24, 0.3.0); KCF 0.563 and DSST 0.354 (2026-11-25, the papers' parameters:
both lose the trucks at their occlusion and wakeboard7's rider, DSST wakeboard10's too, and
DSST's boat1 centre drifts 15-25 px off the 155x319 px boat; OpenCV's KCF scores 0.405). 0.8
ships the authors' details (docs/results.md, "Defaults decided by evidence"): DR²Track 0.959,
STRCF 0.962, BACF 0.721 (the authors' BACF loses both trucks here), and the floors follow
the lowest measured. ECO-HC 0.825 (2026-11-29, issue 40: it loses truck4_1 at the occlusion,
as its authors' code does under Octave). Six sequences are few: a last-bit change in a feature moved a
tracker's mean by up to ±0.05 (measured), hence the margins, and no test of the ranking between
trackers.
"""
import cv2
import numpy as np
import pytest

import dcfkit
from dcfkit.analysis.metrics import average, score_sequence
from dcfkit.datasets import load_dataset
from dcfkit.running.runner import run_pool, usable_cores

FLOORS = {"dr2track": 0.88, "strcf": 0.81, "bacf": 0.64, "kcf": 0.48, "dsst": 0.27,  # measured minus ~0.08
          "eco_hc": 0.75}


@pytest.fixture(scope="module")
def uav123_10fps(shared_data):
    return load_dataset("uav123_10fps", shared_data / "UAV123_10fps")


def one_pass(config, seq):
    return one_pass_each([config], seq)[config]


def one_pass_each(configs, seq) -> dict[str, list]:
    """The boxes of each config's one-pass run of ``seq``, the frames decoded once."""
    trackers = {config: dcfkit.load_tracker(config) for config in configs}
    frame = seq.frame(0)
    for tracker in trackers.values():
        tracker.init(frame, seq.init_box)
    boxes = {config: [tuple(seq.init_box)] for config in configs}
    for i in range(1, len(seq)):
        frame = seq.frame(i)
        for config, tracker in trackers.items():
            boxes[config].append(tracker.update(frame))
    return boxes


@pytest.fixture(scope="module")
def precision(uav123_10fps) -> dict[str, float]:
    """Mean precision of each config in FLOORS: every config is stepped through a sequence
    together, so that each frame is decoded once (decoding a 720p frame costs about what a
    tracker's update does), and the sequences are shared among worker processes, one a core
    (the suite runs one test at a time), longest first so that the workers end together."""
    calls = {seq.name: (one_pass_each, list(FLOORS), seq) for seq in sorted(uav123_10fps, key=lambda s: -len(s))}
    found = {}
    run_pool(calls, usable_cores(), found.__setitem__, crashed)
    return {config: average([score_sequence(found[seq.name][config], seq.ground_truth)
                             for seq in uav123_10fps])["precision"] for config in FLOORS}


def crashed(name, exc):
    """run_pool's ``on_crash``: a worker that failed fails the fixture, naming the sequence."""
    raise RuntimeError(f"tracking {name} failed in its worker: {exc!r}") from exc


@pytest.mark.parametrize("config", sorted(FLOORS))
def test_precision_floor_on_uav123_10fps(config, precision, uav123_10fps):
    assert len(uav123_10fps) == 6
    assert precision[config] >= FLOORS[config]


@pytest.mark.parametrize("dataset,folder,frames", [("dtb70", "DTB70", 120), ("uavdt", "UAVDT", 82)])
def test_dr2track_runs_on_other_benchmarks(dataset, folder, frames, shared_data):
    """One sequence each of DTB70 (Gull1) and UAVDT (S0601): the layouts load and every box is finite.

    No precision floor: Gull1 (a bird in fast flight) swings by ±0.15 with any small change, and in
    S0601 the target is fully occluded by a road sign from frame ~30, where all trackers lose it."""
    (seq,) = load_dataset(dataset, shared_data / folder)
    assert len(seq) == frames
    boxes = np.array(one_pass("dr2track", seq))
    assert boxes.shape == (frames, 4) and np.all(np.isfinite(boxes))
    if dataset == "uavdt":  # before the occlusion it is an easy car
        assert score_sequence(boxes[:25], seq.ground_truth[:25])["precision"] == 1.0


@pytest.mark.parametrize("dataset,folder", [("uav123_10fps", "UAV123_10fps"), ("dtb70", "DTB70"), ("uavdt", "UAVDT")])
def test_real_frames_read_as_opencv_decodes_them(dataset, folder, shared_data):
    """The first, a middle and the last frame of every sequence: read_frame (simplejpeg's decode
    of a clean JPEG) gives cv2.imread's pixels. ``benchmarks/frame_reading.py`` checks them all."""
    for seq in load_dataset(dataset, shared_data / folder):
        for i in (0, len(seq) // 2, len(seq) - 1):
            np.testing.assert_array_equal(seq.frame(i), cv2.imread(str(seq.frames[i]), cv2.IMREAD_COLOR),
                                          err_msg=str(seq.frames[i]))
