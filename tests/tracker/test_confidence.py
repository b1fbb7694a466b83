"""Per-frame confidence: APCE and the peak on hand-made maps, the tracker's last_confidence,
track()'s confidence column, and confidence falling when the frames go wrong."""
import dataclasses
import math

import numpy as np
import pytest

from dcfkit import load_tracker
from dcfkit.datasets.synthetic import make_sequence
from dcfkit.store.files import format_confidence
from dcfkit.experiments.loop import Track, track
from dcfkit.tracker.confidence import NO_CONFIDENCE, Confidence, apce, confidence_of


def test_apce_of_a_single_peak_by_hand():
    r = np.zeros((3, 3))
    r[1, 1] = 4.0  # |4 - 0|² = 16; mean((R - 0)²) = 16 / 9
    assert apce(r) == pytest.approx(9.0)
    assert Confidence.of(r) == Confidence(4.0, pytest.approx(9.0), 4.0)  # no reliability: the peak is the score
    assert Confidence.of(r, 0.25).score == 0.25


def test_apce_of_a_map_with_a_floor_and_a_second_peak_by_hand():
    r = np.array([[1, 1, 1], [1, 5, 3], [1, 1, 1]], dtype=np.float32)
    # min 1: |5 - 1|² = 16; (R - 1)² sums to 16 + 4 = 20 over 9 cells
    assert apce(r) == pytest.approx(16 / (20 / 9))
    c = Confidence.of(r)
    assert c.peak == 5.0 and c.apce == pytest.approx(7.2)
    assert apce(r) < apce(np.where(r == 3, 1, r))  # the second peak lowers it


def test_apce_is_invariant_to_gain_and_offset_and_zero_for_a_flat_map():
    r = np.random.default_rng(1).random((7, 9))
    assert apce(3.5 * r - 2) == pytest.approx(apce(r))
    assert apce(np.full((4, 4), 0.3)) == 0.0


def test_confidence_is_frozen_and_none_is_nan():
    assert all(math.isnan(v) for v in NO_CONFIDENCE.as_tuple())
    assert Confidence.of(None) is NO_CONFIDENCE and Confidence.of(None, 2.0) is NO_CONFIDENCE
    with pytest.raises(dataclasses.FrozenInstanceError):
        Confidence(1.0, 2.0, 1.0).peak = 3.0
    assert format_confidence(np.array([[np.nan] * 3, [0.5, 12.25, 1.5]])) == "nan,nan,nan\n0.5,12.25,1.5\n"


def test_tracker_confidence_is_read_from_its_last_response():
    seq = make_sequence(n_frames=4, seed=2)
    tracker = load_tracker("strcf")
    tracker.init(seq.frames[0], seq.ground_truth[0])
    assert tracker.last_confidence is NO_CONFIDENCE  # frame 1: no response
    tracker.update(seq.frames[1])
    c = tracker.last_confidence
    assert c.peak == pytest.approx(float(tracker.last_response.max()))
    assert c.apce == pytest.approx(apce(tracker.last_response)) and c.apce > 1
    tracker.update(np.zeros_like(seq.frames[2]))  # a blank frame is held: no response
    assert tracker.held_frames == [3] and tracker.last_confidence is NO_CONFIDENCE


def test_track_collects_one_confidence_per_frame_and_keeps_the_boxes():
    seq = make_sequence(n_frames=8, seed=3)
    run = track(load_tracker("strcf"), seq.frames, seq.ground_truth[0])
    assert run.confidence.shape == (8, 3)
    np.testing.assert_array_equal(run.confidence[:, 2], run.confidence[:, 0])  # no reliability: the peak
    assert np.isnan(run.confidence[0]).all() and np.isfinite(run.confidence[1:]).all()
    tracker = load_tracker("strcf")  # the same tracker, never asked for its confidence
    tracker.init(seq.frames[0], seq.ground_truth[0])
    boxes = [seq.ground_truth[0]] + [tracker.update(f) for f in seq.frames[1:]]
    np.testing.assert_array_equal(run.boxes, np.asarray(boxes, dtype=np.float64))


class NoConfidence:
    def init(self, image, box):
        self.box = box

    def update(self, image):
        return self.box


class BrokenConfidence(NoConfidence):
    @property
    def last_confidence(self):
        raise RuntimeError("no")


@pytest.mark.parametrize("kind", [NoConfidence, BrokenConfidence])
def test_trackers_without_a_readable_confidence_give_nan(kind):
    frames = [np.zeros((20, 20), np.uint8)] * 3
    run = track(kind(), frames, (2, 2, 5, 5))
    assert run.confidence.shape == (3, 3) and np.isnan(run.confidence).all()
    assert np.isnan(confidence_of(kind())).all()
    assert Track(np.zeros((2, 4)), np.zeros(2)).confidence.shape == (2, 3)


@pytest.mark.parametrize("config", ["strcf", "kcf", "dr2track"])
def test_confidence_drops_when_the_frames_turn_to_noise(config):
    seq = make_sequence(n_frames=30, seed=0)
    frames = list(seq.frames)
    rng = np.random.default_rng(0)
    for i in range(20, 30):  # from frame 21 on, noise: the target is gone
        frames[i] = rng.integers(0, 256, frames[i].shape, dtype=np.uint8)
    c = track(load_tracker(config), frames, seq.ground_truth[0]).confidence
    before, noise = c[1:20], c[20:]
    assert np.median(noise[:, 1]) < 0.5 * np.median(before[:, 1])  # APCE
    assert np.median(noise[:, 0]) < np.median(before[:, 0])  # peak


# --------------------------------------------------------------------------- result files


def test_eval_writes_time_and_confidence_files_beside_the_boxes(tmp_path):
    import json

    import cv2

    from dcfkit.datasets import Sequence
    from dcfkit.running.evaluation import run_one_pass
    from dcfkit.store.files import checksum
    from dcfkit.store.results import ResultStore, load_results, result_files

    seq = make_sequence(n_frames=10, seed=5)
    paths = []
    for i, image in enumerate(seq.frames):
        paths.append(tmp_path / "data" / f"{i + 1:05d}.png")
        paths[-1].parent.mkdir(exist_ok=True)
        cv2.imwrite(str(paths[-1]), image)
    sequence = Sequence("syn", tuple(paths), seq.ground_truth, {}, "synthetic")
    config = {**load_tracker("strcf").config, "name": "strcf"}
    assert run_one_pass(config, [sequence], tmp_path / "out", progress=False)["done"] == ["syn"]
    d = tmp_path / "out" / "strcf"
    times, confidence = np.loadtxt(d / "syn.time"), np.loadtxt(d / "syn.confidence", delimiter=",")
    assert times.shape == (10,) and (times > 0).all()
    assert confidence.shape == (10, 3) and np.isnan(confidence[0]).all() and (confidence[1:, 1] > 1).all()
    meta = json.loads((d / "syn.json").read_text())
    np.testing.assert_allclose(times, meta["times"], atol=1e-8)
    assert meta["time_sha256"] == checksum((d / "syn.time").read_bytes())
    assert meta["confidence_sha256"] == checksum((d / "syn.confidence").read_bytes())
    # the same boxes as track() gives, and the extra files are never taken for results
    run = track(load_tracker("strcf"), seq.frames, seq.ground_truth[0])
    np.testing.assert_allclose(load_results(tmp_path / "out", "strcf", [sequence])["syn"].boxes, run.boxes, atol=6e-4)
    np.testing.assert_allclose(confidence[1:], run.confidence[1:], rtol=1e-5)
    assert list(result_files(d)) == ["syn"]
    ResultStore(d).write_failure(sequence, {"run_key": "x"}, ValueError("boom"))  # a failure removes them all
    assert sorted(p.name for p in d.iterdir() if p.name != ".locks") == ["syn.error"]
