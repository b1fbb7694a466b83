"""The reset-based experiment on the 8 development sequences, VOT2016's rule against the trax
library's own overlap: the failures the run loop decides, and the accuracy and EAO scored from
them, equal those a loop that asks libtrax makes and scores."""
from __future__ import annotations

import numpy as np
import pytest
from libtrax import Trax, library_path

from dcfkit.analysis.reset_scores import ResetRun, score_resets
from dcfkit.datasets import load_dataset, read_boxes
from dcfkit.experiments.vot import SKIP
from dcfkit.experiments.vot import next_start
from dcfkit.experiments.reset import track_with_resets

TRACKERS = ("KCF", "STRCF")  # one that fails often, one that seldom does


class Replay:
    """A published tracker's one-pass boxes, moved at each start to start from the ground truth:
    a tracker whose boxes are real ones, at no cost."""

    def __init__(self, boxes: np.ndarray, frame: list[int]):
        self.boxes, self.frame = boxes, frame

    def init(self, image, box):
        self.shift = np.asarray(box, dtype=float)[:2] - self.boxes[self.frame[0], :2]

    def update(self, image):
        box = self.boxes[self.frame[0]].copy()
        box[:2] += self.shift
        return box


def dcfkit_run(seq, boxes, size) -> ResetRun:
    frame = [0]

    def read(i):
        frame[0] = i
        return np.broadcast_to(np.zeros(1, np.uint8), (size[1], size[0], 3))  # no decoding: the size is all

    run = track_with_resets(lambda: Replay(boxes, frame), seq, read, rule="vot2016")
    return ResetRun(run.boxes, seq.ground_truth, tuple(run.starts), tuple(run.failures), size, "vot2016")


def libtrax_run(lib: Trax, seq, boxes, size) -> ResetRun:
    """The same replay with the trax client's failure test (rectangles in [0, W] x [0, H]) and the
    MATLAB analysis's overlaps (polygons, unbounded for the accuracy, [0, W - 1] x [0, H - 1] for the EAO)."""
    gt, n = seq.ground_truth, len(seq)
    out, starts, failures = np.full((n, 4), np.nan), [], []
    start = next_start(gt, 0, (size[1], size[0]))
    while start is not None:
        starts.append(start)
        out[start], shift = gt[start], gt[start, :2] - boxes[start, :2]
        for i in range(start + 1, n):
            out[i] = boxes[i] + [*shift, 0, 0]
            if np.isfinite(gt[i]).all() and lib.rectangles(gt[i], out[i], (0, 0, *size)) <= 0:
                failures.append(i)
                break
        else:
            break
        start = next_start(gt, failures[-1] + SKIP, (size[1], size[0]))
    run = ResetRun(out, gt, tuple(starts), tuple(failures), size, "vot2016")
    for name, bounds in (("accuracy_overlaps", None), ("overlaps", (0, 0, size[0] - 1, size[1] - 1))):
        found = np.full(n, np.nan)
        for i in np.flatnonzero(np.isfinite(out).all(axis=1) & np.isfinite(gt).all(axis=1)):
            found[i] = lib.polygons(out[i], gt[i], bounds)
        run.__dict__[name] = found  # the cached overlaps, the library's
    return run


def test_vot2016_scores_on_the_development_sequences_are_libtrax_s(shared_data):
    path = library_path()
    if path is None:
        pytest.skip("vot-trax (its libtrax.so) is not installed: pip install vot-trax, as the test extras do")
    lib = Trax(path)
    ours, theirs, lengths = {}, {}, {}
    for folder in ("UAV123_10fps", "DTB70", "UAVDT"):
        for seq in load_dataset("auto", shared_data / folder):
            height, width = seq.frame(0).shape[:2]
            lengths[seq.name] = len(seq)
            for tracker in TRACKERS:
                boxes = read_boxes(shared_data / "published_results" / tracker / folder / f"{seq.name}.txt")
                ours.setdefault(tracker, {})[seq.name] = dcfkit_run(seq, boxes, (width, height))
                theirs.setdefault(tracker, {})[seq.name] = libtrax_run(lib, seq, boxes, (width, height))
    assert len(lengths) == 8
    for tracker in TRACKERS:
        for name, run in ours[tracker].items():
            assert run.failures == theirs[tracker][name].failures, (tracker, name)
            assert run.starts == theirs[tracker][name].starts, (tracker, name)
    found, expected = score_resets(ours, lengths), score_resets(theirs, lengths)
    for table in ("overall", "per_sequence"):
        for mine, reference in zip(found[table], expected[table]):
            assert mine["tracker"] == reference["tracker"] and mine["failures"] == reference["failures"]
            for score in ("accuracy", "eao") if table == "overall" else ("accuracy",):
                assert mine[score] == pytest.approx(reference[score], abs=1e-6), (table, mine)
    assert sum(r["failures"] for r in found["overall"]) > 20  # restarts happen: failures are compared
