"""Reset-based results are scored only as what they are: one-pass scoring (`report`, `compare`)
refuses them, and `report --experiment reset` scores a run only while its sidecar's starts and
failures are those VOT's rule gives from its boxes and ground truth."""
from __future__ import annotations

import io
import json
import logging
import shutil

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from test_ablation import write_otb
from test_evaluation import Counter

from dcfkit import cli
from dcfkit.analysis.reset_report import resets_problem
from dcfkit.analysis.reset_scores import ResetRun
from dcfkit.datasets import Sequence, load_dataset
from dcfkit.experiments.vot import get_rule
from dcfkit.running.evaluation import run_one_pass
from dcfkit.store.files import format_boxes
from dcfkit.experiments.reset import track_with_resets

N = 30
CONFIG = {"name": "drift", "drift": 4.0}  # 4 px a frame off a 20 px wide target: a failure every few frames


@pytest.fixture(scope="module")
def evaluated(tmp_path_factory):
    """Two synthetic OTB sequences; OUT/drift/ (one pass) and OUT/drift/reset/ of one drifting tracker."""
    tmp = tmp_path_factory.mktemp("resets")
    root, out = tmp / "data", tmp / "out"
    for i, name in enumerate(("seqA", "seqB")):
        write_otb(root, name, seed=i, n_frames=N)
    seqs = load_dataset("otb", root)
    for experiment in ("reset", "ope"):
        run_one_pass(CONFIG, seqs, out, make_tracker=Counter(), progress=False, experiment=experiment)
    return root, out


def report(out, root, tmp_path, *extra) -> int:
    return cli.main(["report", str(out), "--dataset", "otb", "--root", str(root), "--report-dir",
                     str(tmp_path / "report"), *extra])


REFUSED = "holds reset-based runs, not one-pass results (the sidecars of 'seqA' and 1 more record resets); " \
          "score them with dcfkit report --experiment reset"


def test_report_refuses_a_tracker_folder_given_as_out(evaluated, tmp_path, capsys):
    """`report OUT/drift`: its sub-folder reset/ would be a tracker named "reset", scored as one pass."""
    root, out = evaluated
    assert report(out / "drift", root, tmp_path) != 0
    err = capsys.readouterr().err
    assert f"{out / 'drift' / 'reset'} {REFUSED}" in err and "Traceback" not in err


def test_report_refuses_a_reset_folder_named_as_a_tracker(evaluated, tmp_path, capsys):
    root, out = evaluated
    assert report(out, root, tmp_path, "--trackers", f"drift,drift_reset={out / 'drift' / 'reset'}") != 0
    assert REFUSED in capsys.readouterr().err
    assert report(out, root, tmp_path) == 0  # the one-pass results themselves are scored
    assert "drift " in capsys.readouterr().out


@pytest.mark.parametrize("reset_side", [0, 1])
def test_compare_refuses_reset_based_runs_on_either_side(evaluated, capsys, reset_side):
    root, out = evaluated
    folders = [str(out / "drift"), str(out / "drift")]
    folders[reset_side] = str(out / "drift" / "reset")
    assert cli.main(["compare", *folders, "--dataset", "otb", "--root", str(root)]) != 0
    captured = capsys.readouterr()
    assert REFUSED in captured.err and "noise floor" not in captured.out


def test_report_scores_the_reset_runs_as_their_sidecars_say(evaluated, tmp_path):
    """The genuine runs pass the check: nothing is left out."""
    root, out = evaluated
    assert report(out, root, tmp_path, "--experiment", "reset") == 0
    scores = json.loads((tmp_path / "report" / "reset.json").read_text())
    assert scores["left_out"] == {} and scores["overall"][0]["sequences"] == 2
    assert scores["overall"][0]["failures"] > 2


def tampered(evaluated, tmp_path, change) -> tuple:
    """A copy of OUT whose seqB sidecar records ``change(its resets)`` (its checksums still hold)."""
    root, out = evaluated
    copy = tmp_path / "out"
    shutil.copytree(out, copy)
    sidecar = copy / "drift" / "reset" / "seqB.json"
    meta = json.loads(sidecar.read_text())
    resets, said = change(meta["resets"])
    sidecar.write_text(json.dumps({**meta, "resets": resets}))
    return root, copy, said


NOT_RECORDED = "the box does not overlap the ground truth, a failure its sidecar does not record"


@pytest.mark.parametrize("change", [
    lambda r: ({**r, "starts": [1, 18], "failures": []}, f"frame {r['failures'][0]}: {NOT_RECORDED}"),  # an IndexError
    lambda r: ({**r, "starts": [1], "failures": []}, f"frame {r['failures'][0]}: {NOT_RECORDED}"),  # failures hidden
    lambda r: ({**r, "failures": r["failures"][1:]}, f"frame {r['failures'][0]}: {NOT_RECORDED}"),
    lambda r: ({**r, "starts": [1, r["starts"][1] + 1, *r["starts"][2:]]},
               f"frame {r['starts'][1] + 1}: its sidecar records a start where the rule gives none"),
    lambda r: ({**r, "failures": [r["failures"][0] - 1, *r["failures"][1:]]},
               f"frame {r['failures'][0] - 1}: its sidecar records a failure where the box overlaps"),
], ids=["restart-without-failure", "no-failures", "a-failure-dropped", "a-start-moved", "a-failure-moved"])
def test_report_leaves_out_a_run_whose_resets_are_not_its_boxes(evaluated, tmp_path, caplog, change):
    root, copy, expected = tampered(evaluated, tmp_path, change)
    with caplog.at_level(logging.WARNING):
        assert report(copy, root, tmp_path, "--experiment", "reset") == 0
    scores = json.loads((tmp_path / "report" / "reset.json").read_text())
    assert scores["left_out"] == {"seqB": ["drift"]} and scores["overall"][0]["sequences"] == 1
    said = [r.getMessage() for r in caplog.records if "seqB" in r.getMessage()]
    assert len(said) == 1 and "sequence 'seqB' left out" in said[0] and expected in said[0], said


def test_every_run_left_out_is_an_error_not_an_empty_table(evaluated, tmp_path, capsys):
    root, out = evaluated
    shutil.copytree(out, tmp_path / "out")
    for sidecar in (tmp_path / "out" / "drift" / "reset").glob("*.json"):
        sidecar.write_text(json.dumps({**json.loads(sidecar.read_text()), "resets": {"starts": [1], "failures": []}}))
    assert report(tmp_path / "out", root, tmp_path, "--experiment", "reset") != 0
    assert "none of the 2 sequences has a reset-based result that can be scored" in capsys.readouterr().err


# --------------------------------------------------------------------------- the check, by hand

GT_BOX = [10.0, 10.0, 10.0, 10.0]
AWAY = [50.0, 50.0, 10.0, 10.0]
BOUNDS = (80.0, 80.0)


def one_failure(starts=(0, 17), failures=(12,), **frames) -> ResetRun:
    """30 frames tracked on the ground truth, a failure on frame 13 (0-based 12), frames 14-17 not
    tracked, a restart on 18 (12 + 5); ``frames`` (``f<i>=box``) changes boxes."""
    gt = np.tile(GT_BOX, (N, 1))
    boxes = gt.copy()
    boxes[12], boxes[13:17] = AWAY, np.nan
    for key, box in frames.items():
        boxes[int(key[1:])] = box
    return ResetRun(boxes, gt, tuple(starts), tuple(failures), BOUNDS)


@pytest.mark.parametrize("run, problem", [
    (one_failure(), None),
    (one_failure((0,), ()), "frame 13: the box does not overlap the ground truth, a failure its sidecar does not "
                            "record"),
    (one_failure((0, 17), ()), "frame 13: the box does not overlap"),
    (one_failure((0, 18), (12,)), "frame 19: its sidecar records a start where the rule gives none"),
    (one_failure((0,), (12,)), "frame 18: the rule starts the tracker again, its sidecar records no start"),
    (one_failure((17, 0), (12,)), "frame 18: its sidecar records a start where the rule gives none"),
    (one_failure((0, 17), (12, 12)), "frame 13: its sidecar records a failure before its start on frame 18"),
    (one_failure((0, 17), (12, 25)), "frame 26: its sidecar records a failure where the box overlaps"),
    (one_failure((0, 17), (11,)), "frame 12: its sidecar records a failure where the box overlaps"),
    (one_failure((0, 17, 25), (12,)), "frame 26: its sidecar records a start the rule does not give"),
    (one_failure(f14=GT_BOX), "frame 15: a box where no tracker ran"),
    (one_failure(f0=[np.nan] * 4, starts=(0, 17)), None),  # a start's own box is never a failure
])
def test_the_rule_replayed_on_the_boxes(run, problem):
    found = resets_problem(run)
    assert found == problem if problem is None else found.startswith(problem)


def test_a_failure_after_which_no_start_is_due_ends_the_run():
    gt = np.tile(GT_BOX, (N, 1))
    boxes = gt.copy()
    boxes[27], boxes[28:] = AWAY, np.nan  # restart due on frame 33 of 30
    assert resets_problem(ResetRun(boxes, gt, (0,), (27,), BOUNDS)) is None
    assert resets_problem(ResetRun(boxes, gt, (0,), (27, 28), BOUNDS)).startswith(
        "frame 29: its sidecar records a failure the rule does not give")


def test_a_start_moved_past_a_box_off_the_image_and_one_not_moved_both_pass():
    """dcfkit moves a start past a ground truth off the image; 0.9.0 started there."""
    gt = np.tile(GT_BOX, (N, 1))
    gt[17] = [90.0, 10.0, 10.0, 10.0]  # off the 80 px wide image
    boxes = gt.copy()
    boxes[12], boxes[13:17] = AWAY, np.nan
    moved = boxes.copy()
    moved[17] = np.nan
    assert resets_problem(ResetRun(moved, gt, (0, 18), (12,), BOUNDS)) is None
    assert resets_problem(ResetRun(boxes, gt, (0, 17), (12,), BOUNDS)) is None
    assert resets_problem(ResetRun(boxes, gt, (0, 19), (12,), BOUNDS)) is not None


def test_a_decision_the_rounding_of_the_file_could_turn_is_taken_either_way():
    """The run decided on the exact box; the check sees it as the %.3f result file holds it. The
    box's window (its corners floored and ceiled) starts at 18, inside the ground truth's
    10..19, and its first pixel, 18.9996 rounded, is 19: an overlap; the file's 19.000 starts the
    window at 19, where the ground truth's ends: no overlap (trax's windows must overlap)."""
    box, rule = [18.9996, 10.0, 5.0, 10.0], get_rule("vot2016")
    gt = np.tile(GT_BOX, (N, 1))
    boxes = gt.copy()
    boxes[12] = box
    stored = read_boxes_of(boxes)
    assert not rule.failed(box, gt[12], BOUNDS) and rule.failed(stored[12], gt[12], BOUNDS)
    assert resets_problem(ResetRun(stored, gt, (0,), (), BOUNDS)) is None


def read_boxes_of(boxes: np.ndarray) -> np.ndarray:
    """``boxes`` as a result file gives them back (``%.3f``, 1-based)."""
    return np.loadtxt(io.StringIO(format_boxes(boxes)), delimiter=",", ndmin=2) - [1.0, 1.0, 0.0, 0.0]


class Wander:
    """A tracker that returns the ground truth moved by a scripted step per frame (drifting off,
    jumping, sitting on the image border, or one frame with no box at all)."""

    def __init__(self, gt, steps):
        self.gt, self.steps = gt, steps

    def init(self, image, box):
        self.box, self.k = np.asarray(box, dtype=float), 0

    def update(self, image):
        self.k += 1
        step = self.steps[self.k % len(self.steps)]
        return [np.nan] * 4 if step is None else self.box + step


step = st.one_of(st.none(), st.lists(st.floats(-12, 12, allow_nan=False).map(lambda v: round(v, 4)),
                                     min_size=4, max_size=4))


@given(steps=st.lists(step, min_size=1, max_size=8), x0=st.floats(-20, 70), hidden=st.sets(st.integers(0, N - 1)))
def test_every_genuine_run_passes_the_check(steps, x0, hidden):
    """Runs of the real frame loop, stored as a result file stores them, always pass: the check
    never loses a result (ground truth in and off the 80x80 image, frames without one)."""
    gt = np.column_stack([x0 + np.arange(N) * 1.7, np.full(N, 30.0), np.full(N, 10.0), np.full(N, 12.0)])
    gt[sorted(hidden)] = np.nan
    seq = Sequence("s", tuple(f"{k:04d}.jpg" for k in range(N)), gt, dataset="fake")
    image = np.zeros((80, 80, 3), np.uint8)
    run = track_with_resets(lambda: Wander(gt, steps), seq, lambda i: image)
    stored = ResetRun(read_boxes_of(run.boxes), gt, tuple(run.starts), tuple(run.failures), BOUNDS)
    assert resets_problem(stored) is None
