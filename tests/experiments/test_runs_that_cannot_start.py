"""A run no tracker can start from is left out (TRE, SRE) or started later (reset-based), and
the sequence's other runs are kept and scored (docs/evaluation.md, "Runs that cannot start")."""
from __future__ import annotations

import json

import cv2
import numpy as np
import pytest

from dcfkit import experiments
from dcfkit.analysis.scoring import evaluate
from dcfkit.datasets import DatasetError, DatasetWarning, Sequence
from dcfkit.experiments import left_out_runs, runs_by_sequence
from dcfkit.experiments.otb import SRE_SHIFTS, tre_starts
from dcfkit.experiments.starts import start_problem
from dcfkit.running.evaluation import run_one_pass
from dcfkit.experiments.reset import SKIP, track_with_resets
from dcfkit.store.results import load_results
from dcfkit.tracker.checks import check_box

N, HEIGHT, WIDTH = 30, 40, 50
CONFIG = {"name": "still"}


class Still:
    """Starts as dcfkit's tracker does (refusing a box off the image) and stays where it started."""

    def __init__(self, config=None):
        self.box = None

    def init(self, image, box):
        self.box = check_box(box, image.shape)

    def update(self, image):
        return self.box


@pytest.fixture(autouse=True)
def warned_afresh(monkeypatch):
    monkeypatch.setattr(experiments, "_SAID", set())  # each test sees its own warnings


def sequence(folder, name: str, gt: np.ndarray) -> Sequence:
    folder.mkdir(parents=True, exist_ok=True)
    paths = tuple(folder / f"{name}_{k + 1:04d}.jpg" for k in range(len(gt)))
    for k, path in enumerate(paths):
        cv2.imwrite(str(path), np.full((HEIGHT, WIDTH, 3), 4 * k, np.uint8))
    return Sequence(name, paths, gt, {}, "fake")


def walking(n: int = N) -> np.ndarray:
    return np.array([[5.0 + k % 3, 6, 8, 9] for k in range(n)])


def scored(tmp_path, sequences, experiment) -> tuple[dict, dict]:
    """(sequence -> the frames its score pools, run_one_pass's summary); a sequence without
    every run it should have is left out of the scores."""
    summary = run_one_pass(CONFIG, sequences, tmp_path / "out", make_tracker=Still, progress=False,
                           experiment=experiment)
    runs = runs_by_sequence(sequences, experiment)
    results = load_results(tmp_path / "out" / "still", experiment, [r for found in runs.values() for r in found])
    evaluation = evaluate({"still": results}, sequences, experiment=experiment, runs=runs, missing="skip")
    return {row["sequence"]: row["frames"] for row in evaluation.per_sequence}, summary


def test_start_problem_says_what_no_tracker_can_start_from():
    assert start_problem([0, 0, 1, 1], (HEIGHT, WIDTH)) is None
    assert start_problem([-5, -5, 6, 6], (HEIGHT, WIDTH)) is None  # one pixel inside
    assert start_problem([WIDTH, 0, 5, 5], (HEIGHT, WIDTH)) == f"lies outside the {WIDTH}x{HEIGHT} image"
    assert start_problem([0, -6, 5, 6], (HEIGHT, WIDTH)) == f"lies outside the {WIDTH}x{HEIGHT} image"
    assert start_problem([3, 3, 0, 5], (HEIGHT, WIDTH)) == "has no width"
    assert start_problem([3, 3, 5, -1], (HEIGHT, WIDTH)) == "has no height"
    assert start_problem([np.nan, 3, 5, 5], (HEIGHT, WIDTH)) == "is NaN or infinite"


def test_an_sre_shift_clipped_to_no_width_is_left_out_and_the_sequence_scored_on_the_others(tmp_path):
    gt = walking()
    gt[0] = [WIDTH - 1, 10, 1, 9]  # one pixel wide at the right border: "right" moves it out, no width left
    edge, other = sequence(tmp_path / "data", "edge", gt), sequence(tmp_path / "data", "other", walking())
    with pytest.warns(DatasetWarning, match=r"SRE run 'edge_002' \(shift right\) cannot start: its box "
                                            r"\(50, 10, 0, 9\) has no width; .* scored on its other 11 runs"):
        frames, summary = scored(tmp_path, [edge, other], "sre")
    assert SRE_SHIFTS[1] == "right" and not summary["failed"]
    assert len(summary["done"]) == 23 and "edge_002" not in summary["done"] and "edge_003" in summary["done"]
    assert frames == {"edge": 11 * N, "other": 12 * N}  # the edge sequence is scored on its 11 runs
    assert left_out_runs([edge, other], "sre") == {
        "edge_002": "SRE run 'edge_002' (shift right) cannot start: its box (50, 10, 0, 9) has no width"}


def test_a_tre_start_outside_the_image_is_left_out_and_the_others_keep_their_names(tmp_path):
    gt = walking()
    starts = tre_starts(gt)
    assert starts[2:4] == [1, 1]  # 30 frames: runs 3 and 4 both start on frame 2, as the toolkit's do
    gt[1] = [WIDTH + 5, 6, 8, 9]  # valid for the toolkit (all > 0), but right of the image
    seq = sequence(tmp_path / "data", "late", gt)
    with pytest.warns(DatasetWarning) as said:
        frames, summary = scored(tmp_path, [seq], "tre")
    assert [str(w.message).split(";")[0] for w in said] == [
        f"TRE run 'late_00{k}' (from frame 2) cannot start: its box ({WIDTH + 5}, 6, 8, 9) lies outside the "
        f"{WIDTH}x{HEIGHT} image" for k in (3, 4)]
    kept = {f"late_{k:03d}": N - s for k, s in enumerate(starts, 1) if s != 1}
    assert not summary["failed"] and sorted(summary["done"]) == sorted(kept) and len(kept) == len(starts) - 2
    assert frames == {"late": sum(kept.values())}  # the sequence is scored on its other runs


def test_a_sequence_none_of_whose_runs_can_start_is_an_error_naming_it(tmp_path):
    gt = walking()
    gt[0] = [WIDTH + 1, 6, 8, 9]  # every SRE shift of it stays off the image
    with pytest.raises(DatasetError, match=r"sequence 'gone': no SRE run can start; SRE run 'gone_001'"):
        runs_by_sequence([sequence(tmp_path, "gone", gt)], "sre")


def test_a_reset_due_on_a_box_outside_the_image_starts_at_the_next_frame_inside(tmp_path):
    gt = walking()
    gt[10:16] = [WIDTH + 3, 6, 8, 9]  # frames 11-16 off the image: a failure on 11, its restart due on 16
    gt[0] = [-20, 6, 8, 9]  # frame 1 too: the first start waits for frame 2
    seq = sequence(tmp_path, "gap", gt)
    run = track_with_resets(Still, seq, seq.frame)
    assert run.starts == [1, 16] and run.failures == [10] and 10 + SKIP == 15
    assert run.record() == {"rule": "vot2016", "starts": [2, 17], "failures": [11], "moved": [[1, 2], [16, 17]]}
    assert np.isnan(run.boxes[11:16]).all() and np.isfinite(run.boxes[16:]).all()
    summary = run_one_pass(CONFIG, [seq], tmp_path / "out", make_tracker=Still, progress=False, experiment="reset")
    assert summary["done"] == ["gap"] and not summary["failed"]
    meta = json.loads((tmp_path / "out" / "still" / "reset" / "gap.json").read_text())
    assert meta["resets"] == {"rule": "vot2016", "starts": [2, 17], "failures": [11], "moved": [[1, 2], [16, 17]]}


def test_a_reset_based_run_that_can_start_nowhere_fails_and_is_not_scored_as_perfect(tmp_path):
    gone = sequence(tmp_path, "gone", np.array([[WIDTH + 3, 6, 8, 9]] * N))  # off the image on every frame
    with pytest.raises(DatasetError, match=r"sequence 'gone': no frame's ground truth is valid and inside the image"):
        track_with_resets(Still, gone, gone.frame)
    summary = run_one_pass(CONFIG, [gone, sequence(tmp_path, "here", walking())], tmp_path / "out",
                           make_tracker=Still, progress=False, experiment="reset")
    assert summary["done"] == ["here"] and list(summary["failed"]) == ["gone"]
