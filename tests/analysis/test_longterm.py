"""VOT-LT tracking precision, recall and F: hand-computed curves, the toolkit's thresholds, the
confidence reader on both file formats, and the long-term table of ``dcfkit report``."""
from __future__ import annotations

import hashlib
import json
import math
from pathlib import Path

import cv2
import numpy as np
import pytest

from dcfkit import cli
from dcfkit.analysis.longterm import frame_overlaps, long_term_scores, predicted_scores, sequence_curves, thresholds
from dcfkit.analysis.longterm_report import score_long_term
from dcfkit.datasets import DatasetError, Sequence
from dcfkit.experiments import runs_by_sequence
from dcfkit.store.results import read_confidence

NAN = math.nan

# Two sequences, frame 1 first (the initialisation: no confidence, ground truth present).
# A: conf    nan  0.9  0.6  0.3     0.8     overlap  1  0.8  0.5  0.7*  0.4   (* ground truth absent:
#    taken as 0);  ground truth present at frames 1, 2, 3, 5: 4 frames.
# B: conf    nan  0.6  nan  0.2             overlap  1  0.9  0    0.6   ; present at 1, 2, 4: 3 frames
#    (frame 3 absent, and the tracker says so: no confidence).
A = (np.array([1, .8, .5, .7, .4]), np.array([1, 1, 1, 0, 1], bool), np.array([NAN, .9, .6, .3, .8]))
B = (np.array([1, .9, 0, .6]), np.array([1, 1, 0, 1], bool), np.array([NAN, .6, NAN, .2]))
# Pooled confidences, highest first: .9 .8 .6 .6 .3 .2 (6 <= 98: all are thresholds), with +inf, -inf.
TAUS = [math.inf, .9, .8, .6, .6, .3, .2, -math.inf]
# A, frames present at tau -> Pr = mean overlap, Re = sum / 4:
#   inf: none -> 1, 0;  .9: {.8} -> .8, .2;  .8: {.8, .4} -> .6, .3;  .6: {.8, .5, .4} -> 17/30, .425;
#   .3, .2, -inf: {.8, .5, 0, .4} -> .425, .425 (frame 1 never: its confidence is NaN)
PR_A, RE_A = [1, .8, .6, 17 / 30, 17 / 30, .425, .425, .425], [0, .2, .3, .425, .425, .425, .425, .425]
# B, Re = sum / 3:  inf, .9, .8: none -> 1, 0;  .6, .3: {.9} -> .9, .3;  .2, -inf: {.9, .6} -> .75, .5
PR_B, RE_B = [1, 1, 1, .9, .9, .9, .75, .75], [0, 0, 0, .3, .3, .3, .5, .5]
# Averaged:  Pr  1   .9   .8   11/15   11/15   .6625  .5875  .5875
#            Re  0   .1   .15  .3625   .3625   .3625  .4625  .4625
#            F   0   .18  .2526 .4852  .4852   .4686  .5176  .5176
# F = 2 Pr Re / (Pr + Re); max at tau = .2 (and -inf: the first, highest tau is taken):
# F = 2 (47/80)(37/80) / (84/80) = 3478 / 6720.


def test_hand_computed_curves_of_two_sequences():
    taus = thresholds(np.concatenate([A[2], B[2]]))
    assert taus.tolist() == TAUS
    pr_a, re_a = sequence_curves(*A, taus)
    pr_b, re_b = sequence_curves(*B, taus)
    assert pr_a == pytest.approx(PR_A, abs=1e-12) and re_a == pytest.approx(RE_A, abs=1e-12)
    assert pr_b == pytest.approx(PR_B, abs=1e-12) and re_b == pytest.approx(RE_B, abs=1e-12)
    scores = long_term_scores([A, B])
    assert scores["f"] == pytest.approx(3478 / 6720, abs=1e-12)
    assert (scores["precision"], scores["recall"]) == pytest.approx((47 / 80, 37 / 80), abs=1e-12)
    assert scores["threshold"] == 0.2 and scores["sequences"] == 2
    assert scores["f_curve"][:3] == pytest.approx([0, .18, 2 * .8 * .15 / .95], abs=1e-12)


def test_thresholds_take_the_toolkits_evenly_spaced_pooled_scores():
    """200 scores 200..1: d = floor(200 / 98) = 2, indices round(linspace(2, 198, 98)): from the
    third-highest score to the third-lowest, 98 of them between +inf and -inf; NaN is dropped."""
    taus = thresholds(np.r_[np.arange(1.0, 201.0), NAN])
    assert len(taus) == 100 and taus[0] == math.inf and taus[-1] == -math.inf
    assert taus[1] == 198 and taus[-2] == 2 and np.all(np.diff(taus) < 0)
    assert thresholds([NAN]).tolist() == [math.inf, -math.inf]


def test_no_prediction_has_precision_one_and_frame_one_counts_in_recall_only():
    confidence = predicted_scores([5.0, NAN, NAN], np.zeros((3, 4)), 3)
    pr, re = sequence_curves(np.ones(3), np.ones(3, bool), confidence, [math.inf, -math.inf])
    assert pr.tolist() == [1.0, 1.0] and re.tolist() == [0.0, 0.0]  # frame 1 (5.0) is no prediction
    assert np.isnan(predicted_scores([5.0, 1.0], np.zeros((2, 4)), 3)).tolist() == [True, False, True]
    boxes = np.array([[0, 0, 10, 10], [0, 0, 10, 10], [NAN] * 4])
    assert np.isnan(predicted_scores([1, 2, 3], boxes, 3)).tolist() == [True, False, True]  # a NaN box: none
    overlap, present = frame_overlaps([[0, 0, 10, 10], [5, 0, 10, 10]], [[0, 0, 10, 10], [NAN] * 4])
    assert overlap.tolist() == [1.0, 0.0] and present.tolist() == [True, False]


def test_overlaps_are_bounded_by_the_image_as_the_toolkit_bounds_them():
    """A box half left of the image on a ground truth at its edge: IoU 100/200 unbounded, 1 once
    both are cut to the image's pixels (vot-toolkit's bounded=True); a NaN box overlaps nothing."""
    pred, gt = [[-10, 0, 20, 10], [NAN] * 4], [[0, 0, 10, 10]] * 2
    assert frame_overlaps(pred, gt)[0].tolist() == [0.5, 0.0]
    assert frame_overlaps(pred, gt, (100, 100))[0].tolist() == [1.0, 0.0]


def test_the_reader_takes_score_of_three_columns_and_peak_of_two(tmp_path):
    three, two = tmp_path / "a.confidence", tmp_path / "b.confidence"
    three.write_text("nan,nan,nan\n0.5,3,0.25\n0.4,2,nan\n")
    two.write_text("nan,nan\n0.5,3\n0.4,2")  # no final line break
    assert np.array_equal(read_confidence(three), [NAN, 0.25, NAN], equal_nan=True)
    assert np.array_equal(read_confidence(two), [NAN, 0.5, 0.4], equal_nan=True)
    assert read_confidence(three, hashlib.sha256(three.read_bytes()).hexdigest()).shape == (3,)
    with pytest.raises(DatasetError, match=r"a\.confidence is not the file its run wrote"):
        read_confidence(three, "0" * 64)


@pytest.mark.parametrize("text, line", [("0.5,1\n0.4,x\n", 2), ("0.5,1\n0.4,1,0.3\n", 2), ("0.5\n", 1),
                                        ("0.5,1\n\n0.3,1\n", 2), ("1,2,3,4\n", 1)])
def test_a_malformed_confidence_file_names_the_file_and_line(tmp_path, text, line):
    path = tmp_path / "seq.confidence"
    path.write_text(text)
    with pytest.raises(DatasetError, match=rf"seq\.confidence, line {line}: .* comma-separated numbers"):
        read_confidence(path)
    with pytest.raises(DatasetError, match=r"cannot read .*none\.confidence"):
        read_confidence(tmp_path / "none.confidence")


def test_tre_is_not_scored_and_says_so():
    assert "one-pass runs (OPE) only" in score_long_term({}, {}, [], "tre")["skipped"]


# --------------------------------------------------------------------------- the report

GT = np.array([[20.0, 20.0, 10.0, 10.0]] * 6)


def _sequence(root: Path, name: str, absent: tuple[int, ...]) -> Sequence:
    """Six frames of 64 x 64 pixels (the overlaps are bounded by the image)."""
    gt = GT.copy()
    gt[list(absent)] = NAN
    (root / name).mkdir(parents=True)
    frames = tuple(root / name / f"{k:05d}.png" for k in range(6))
    for frame in frames:
        cv2.imwrite(str(frame), np.zeros((64, 64, 3), np.uint8))
    return Sequence(name=name, frames=frames, ground_truth=gt, attributes={}, dataset="test")


def _write(folder: Path, name: str, boxes: np.ndarray, confidence: str | None) -> None:
    folder.mkdir(parents=True, exist_ok=True)
    (folder / f"{name}.txt").write_text("".join(f"{x + 1:.3f},{y + 1:.3f},{w:.3f},{h:.3f}\n" for x, y, w, h in boxes))
    if confidence is not None:
        (folder / f"{name}.confidence").write_text(confidence)


def _results(out: Path, malformed: bool = False) -> None:
    """x: on a, IoU 1 but frame 6 (IoU 0: the box is off the image), scores (column 3) .9 .8 .3 (frame 4, ground truth absent)
    .7 .6, peaks all 5; on b (2 columns), IoU 1, peaks .5 .4 nan .2 .1. y: boxes only. z: a bad line."""
    a = GT.copy()
    a[5, 0] += 50
    _write(out / "x", "a", a, "nan,nan,nan\n" + "".join(f"5,1,{s}\n" for s in (.9, .8, .3, .7, .6)))
    _write(out / "x", "b", GT, "nan,nan\n" + "".join(f"{p},1\n" for p in (.5, .4, "nan", .2, .1)))
    for name in "ab":
        _write(out / "y", name, GT, None)
        _write(out / "z", name, GT, "nan,nan\n0.5,1\n0.5;1\n" + "0.5,1\n" * 3 if malformed else None)


def test_report_writes_the_long_term_table_and_curves(tmp_path, monkeypatch, capsys):
    """Pooled scores .9 .8 .7 .6 .5 .4 .3 .2 .1. a has 5 frames with ground truth, b 6 (frame 1
    in both, never predicted). At tau = .1: a predicts frames 2-6 (IoU 1, 1, 0 absent, 1, 0): Pr 3/5,
    Re 3/5; b frames 2, 3, 5, 6 (IoU 1): Pr 1, Re 4/6. Averaged Pr .8, Re 19/30, F = 30.4/43 = .707,
    the maximum (at .2: Pr .8, Re .55, F .652; at .4: Pr .875, Re 14/30, F .609; higher taus less)."""
    import dcfkit.cli.evaluate

    _results(tmp_path / "out", malformed=True)
    sequences = [_sequence(tmp_path / "data", "a", (3,)), _sequence(tmp_path / "data", "b", ())]
    monkeypatch.setattr(dcfkit.cli.evaluate, "load_datasets", lambda *a, **k: sequences)
    assert cli.main(["report", str(tmp_path / "out"), "--root", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "long-term measures: tracking precision Pr, recall Re" in out and "continuous IoU" not in out
    row = next(line.split() for line in out.splitlines() if line.startswith("x ") and "0.707" in line)
    assert row == ["x", "0.707", "0.800", "0.633", "0.100", "2", "1"]
    assert "no long-term scores for y: no " in out and "y/a.confidence (results imported" in out
    assert "no long-term scores for z: " in out and "z/a.confidence, line 3: '0.5;1'" in out
    report = tmp_path / "out_report"
    record = json.loads((report / "report.json").read_text())["long_term"]
    (x,) = record["rows"]
    assert x["f"] == pytest.approx(30.4 / 43) and (x["precision"], x["recall"]) == pytest.approx((.8, 19 / 30))
    assert x["threshold"] == pytest.approx(.1) and set(record["left_out"]) == {"y", "z"}
    assert "| x | 0.707 | 0.800 | 0.633 | 0.100 | 2 | 1 |" in (report / "longterm.md").read_text()
    curves = (report / "longterm_curves.csv").read_text().splitlines()
    assert curves[0] == "tracker,threshold,precision,recall,f" and len(curves) == 1 + 11
    assert curves[1] == "x,inf,1.0,0.0,0.0" and curves[-1].startswith("x,-inf,0.8")
    assert (report / "longterm.csv").read_text().splitlines()[0] == "tracker,f,precision,recall,threshold,sequences,absent"


def test_a_sequence_without_readable_frames_has_unbounded_overlaps_and_says_so(tmp_path, monkeypatch, capsys):
    import dcfkit.cli.evaluate

    _results(tmp_path / "out")
    sequences = [Sequence(name=n, frames=tuple(Path(f"{k:05d}.jpg") for k in range(6)), ground_truth=GT.copy(),
                          attributes={}, dataset="test") for n in "ab"]
    monkeypatch.setattr(dcfkit.cli.evaluate, "load_datasets", lambda *a, **k: sequences)
    assert cli.main(["report", str(tmp_path / "out"), "--root", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "overlaps of 2 sequences are the continuous IoU, not bounded by the image (their frame 1 cannot be " \
           "read): a, b" in out
    assert json.loads((tmp_path / "out_report" / "report.json").read_text())["long_term"]["unbounded"] == ["a", "b"]


def test_an_sre_report_says_it_has_no_long_term_measures(tmp_path, monkeypatch, capsys):
    """SRE runs start from shifted boxes: the report says the measures are OPE's only and writes no
    long-term file."""
    import dcfkit.cli.evaluate

    sequences = [_sequence(tmp_path / "data", n, ()) for n in "ab"]
    monkeypatch.setattr(dcfkit.cli.evaluate, "load_datasets", lambda *a, **k: sequences)
    for runs in runs_by_sequence(sequences, "sre").values():
        for run in runs:
            _write(tmp_path / "out" / "x" / "sre", run.name, GT[:len(run)], "nan,nan\n" + "0.5,1\n" * (len(run) - 1))
    assert cli.main(["report", str(tmp_path / "out"), "--root", str(tmp_path), "--experiment", "sre"]) == 0
    assert "long-term measures are computed for one-pass runs (OPE) only, not for SRE" in capsys.readouterr().out
    report = tmp_path / "out_report" / "sre"
    assert "skipped" in json.loads((report / "report.json").read_text())["long_term"]
    assert not list(report.glob("longterm*"))
