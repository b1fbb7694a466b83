"""evaluate(): its statistics over sequences, against scipy on the per-sequence scores."""
from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import cv2
import numpy as np
import pytest
from scipy import stats

from dcfkit import cli
from dcfkit.analysis.scoring import evaluate
from dcfkit.analysis.tables import statistics_lines
from dcfkit.datasets import DatasetError, Sequence

GT = np.array([[20.0, 20.0, 10.0, 10.0]] * 10)


def sequence(name: str) -> Sequence:
    return Sequence(name=name, frames=tuple(Path(f"{k:05d}.jpg") for k in range(10)), ground_truth=GT.copy(),
                    attributes={}, dataset="test")


def shifted(px: float) -> np.ndarray:
    boxes = GT.copy()
    boxes[1:, 0] += px
    return boxes


SEQUENCES = [sequence(n) for n in "abcde"]
RESULTS = {"near": {s.name: shifted(k) for k, s in enumerate(SEQUENCES)},          # 0..4 px off
           "far": {s.name: shifted(2 * k + 1) for k, s in enumerate(SEQUENCES)},   # 1..9 px off
           "same": {s.name: shifted(k) for k, s in enumerate(SEQUENCES)}}          # as near


def write_results(out: Path, results: dict) -> None:
    """``results`` (tracker -> sequence -> 0-based boxes) as ``OUT/<tracker>/<sequence>.txt``, 1-based."""
    for tracker, by_sequence in results.items():
        folder = out / tracker
        folder.mkdir(parents=True)
        for name, boxes in by_sequence.items():
            (folder / f"{name}.txt").write_text("".join(f"{x + 1:.3f},{y + 1:.3f},{w:.3f},{h:.3f}\n"
                                                        for x, y, w, h in boxes))


def test_each_tracker_has_its_interval_and_each_other_its_paired_difference_from_the_best():
    ev = evaluate(RESULTS, SEQUENCES)
    st = ev.statistics
    auc = {t: np.array([r["auc"] for r in ev.per_sequence if r["tracker"] == t]) for t in RESULTS}
    best = ev.overall[0]["tracker"]
    assert st.baseline == best in ("near", "same") and st.sequences == 5
    ci = stats.bootstrap((auc["far"],), np.mean, method="BCa", rng=np.random.default_rng(0)).confidence_interval
    assert st.means["far"]["auc"].as_record() == pytest.approx({"mean": auc["far"].mean(), "ci_low": ci.low,
                                                                 "ci_high": ci.high, "n": 5})
    far = st.differences["far"]["auc"]
    assert far.mean == pytest.approx((auc["far"] - auc[best]).mean())
    assert far.wilcoxon_p == pytest.approx(stats.wilcoxon(auc["far"] - auc[best]).pvalue)
    assert (far.won, far.lost) == (0, int(np.sum(auc["far"] < auc[best])))
    other = "same" if best == "near" else "near"
    tie = st.differences[other]["auc"]
    assert (tie.mean, tie.wilcoxon_p, tie.tied, tie.significant) == (0, 1.0, 5, False)
    # Holm over the two comparisons: the tie's p of 1 leaves far's p doubled
    assert far.holm_p == pytest.approx(min(1.0, 2 * far.wilcoxon_p))
    assert ev.as_record()["statistics"] == st


def test_report_prints_and_writes_the_statistics(tmp_path, monkeypatch, capsys):
    import dcfkit.cli.evaluate

    write_results(tmp_path / "out", RESULTS)
    monkeypatch.setattr(dcfkit.cli.evaluate, "load_datasets", lambda *a, **k: SEQUENCES)
    assert cli.main(["report", str(tmp_path / "out"), "--root", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "statistics over 5 sequences: 95% BCa bootstrap" in out and "far - " in out and "(Holm " in out
    written = (tmp_path / "out_report" / "statistics.txt").read_text()
    assert written.splitlines()[3] == out.split("\n\n")[-2].splitlines()[0]
    assert written.startswith("experiment OPE (one-pass evaluation") and written.splitlines()[1].startswith("protocol ")


def test_report_writes_the_statistics_as_one_flat_table_in_markdown_and_csv(tmp_path, monkeypatch):
    """statistics.csv: a row per tracker and score holding report.json's statistics at full
    precision (the difference's keys prefixed d_, none for the baseline), the protocol and
    experiment as last columns; statistics.md: the same rows under the experiment and protocol."""
    import csv

    import dcfkit.cli.evaluate

    write_results(tmp_path / "out", RESULTS)
    monkeypatch.setattr(dcfkit.cli.evaluate, "load_datasets", lambda *a, **k: SEQUENCES)
    assert cli.main(["report", str(tmp_path / "out"), "--root", str(tmp_path)]) == 0
    folder = tmp_path / "out_report"
    statistics = json.loads((folder / "report.json").read_text())["statistics"]
    rows = list(csv.DictReader((folder / "statistics.csv").open()))
    assert len(rows) == sum(len(scores) for scores in statistics["means"].values()) == 3 * 2
    for row in rows:
        mean = statistics["means"][row["tracker"]][row["score"]]
        assert float(row["mean"]) == mean["mean"] and float(row["ci_low"]) == mean["ci_low"]
        difference = statistics["differences"].get(row["tracker"], {}).get(row["score"])
        if difference is None:  # the baseline
            assert row["tracker"] == statistics["baseline"] and row["d_mean"] == row["d_holm_p"] == ""
        else:
            assert float(row["d_mean"]) == difference["mean"] and float(row["d_holm_p"]) == difference["holm_p"]
            assert row["d_significant"] == str(difference["significant"])
        assert (row["protocol"], row["experiment"]) == ("otb", "ope")
    markdown = (folder / "statistics.md").read_text().splitlines()
    assert markdown[0].startswith("experiment OPE (one-pass evaluation") and markdown[1].startswith("protocol otb")
    assert markdown[3].startswith("| tracker | score | mean | ci_low | ci_high |") and len(markdown) == 7 + len(rows)
    assert markdown[-1].startswith(f"d_: the paired difference from {statistics['baseline']}. Over 5 sequences: 95%")


def test_report_takes_the_differences_from_the_baseline_it_is_given(tmp_path, monkeypatch, capsys):
    """``--baseline far``: every other tracker's paired difference is from far (the worst here),
    in the printed LaTeX table and in report.json; a name that is no tracker is one clear error."""
    import dcfkit.cli.evaluate

    write_results(tmp_path / "out", RESULTS)
    monkeypatch.setattr(dcfkit.cli.evaluate, "load_datasets", lambda *a, **k: SEQUENCES)
    report = ["report", str(tmp_path / "out"), "--root", str(tmp_path)]
    assert cli.main(report + ["--baseline", "far", "--format", "latex"]) == 0
    assert "the paired difference from far" in capsys.readouterr().out
    statistics = json.loads((tmp_path / "out_report" / "report.json").read_text())["statistics"]
    assert statistics["baseline"] == "far" and set(statistics["differences"]) == {"near", "same"}
    auc = {t: np.array([r["auc"] for r in evaluate(RESULTS, SEQUENCES).per_sequence if r["tracker"] == t])
           for t in RESULTS}
    assert statistics["differences"]["near"]["auc"]["mean"] == pytest.approx((auc["near"] - auc["far"]).mean())
    assert cli.main(report + ["--baseline", "nobody"]) == 2
    err = capsys.readouterr().err
    assert "--baseline 'nobody': no such tracker in this report; its trackers are" in err and "far" in err
    assert len(err.strip().splitlines()) == 1


def test_a_missing_result_is_left_out_and_named_unless_asked_to_fail():
    partial = {**RESULTS, "far": {k: v for k, v in RESULTS["far"].items() if k != "c"}}
    skipped = evaluate(partial, SEQUENCES, missing="skip")
    assert skipped.settings["left_out"] == {"c": ["far"]} and skipped.settings["missing"] == "skip"
    assert {r["sequence"] for r in skipped.per_sequence} == {"a", "b", "d", "e"}
    assert all(r["sequences"] == 4 and r["missing"] == 0 for r in skipped.overall)
    near = np.mean([r["auc"] for r in evaluate(RESULTS, SEQUENCES).per_sequence
                    if r["tracker"] == "near" and r["sequence"] != "c"])
    assert next(r for r in skipped.overall if r["tracker"] == "near")["auc"] == pytest.approx(near)
    failed = evaluate(partial, SEQUENCES, missing="fail")  # the toolkits' way: c scores 0 for far
    far = next(r for r in failed.overall if r["tracker"] == "far")
    assert far["missing"] == 1 and far["sequences"] == 5 and failed.settings["left_out"] == {}
    assert next(r for r in failed.per_sequence if r["tracker"] == "far" and r["sequence"] == "c")["auc"] == 0


def test_no_complete_sequence_is_an_error_that_says_what_to_do():
    disjoint = {"x": {"a": RESULTS["near"]["a"]}, "y": {"b": RESULTS["near"]["b"]}}
    with pytest.raises(DatasetError, match=r"no sequence has a result from every tracker .*--missing fail"):
        evaluate(disjoint, SEQUENCES[:2], missing="skip")
    with pytest.raises(ValueError, match="missing must be one of skip, fail"):
        evaluate(RESULTS, SEQUENCES, missing="drop")


def test_report_names_what_it_left_out(tmp_path, monkeypatch, capsys):
    import dcfkit.cli.evaluate

    write_results(tmp_path / "out", {**RESULTS, "far": {k: v for k, v in RESULTS["far"].items() if k != "c"}})
    monkeypatch.setattr(dcfkit.cli.evaluate, "load_datasets", lambda *a, **k: SEQUENCES)
    assert cli.main(["report", str(tmp_path / "out"), "--root", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "left out: c (no result from far; --missing fail scores it as a failure)" in out
    assert "statistics over 4 sequences" in out
    assert cli.main(["report", str(tmp_path / "out"), "--root", str(tmp_path), "--missing", "fail"]) == 0
    out = capsys.readouterr().out
    assert "left out" not in out and "statistics over 5 sequences" in out


def test_published_results_join_a_report_under_a_name_of_their_own(tmp_path, monkeypatch, capsys):
    import dcfkit.cli.evaluate

    for tracker, by_sequence in (("near", RESULTS["near"]), ("published/far", RESULTS["far"])):
        folder = tmp_path / tracker
        folder.mkdir(parents=True)
        for name, boxes in by_sequence.items():
            (folder / f"{name}.txt").write_text("".join(f"{x + 1:.3f},{y + 1:.3f},{w:.3f},{h:.3f}\n"
                                                        for x, y, w, h in boxes))
    monkeypatch.setattr(dcfkit.cli.evaluate, "load_datasets", lambda *a, **k: SEQUENCES)
    named = f"Far (paper)={tmp_path / 'published' / 'far'}"
    assert cli.main(["report", str(tmp_path), "--root", str(tmp_path), "--trackers", f"near,{named}",
                     "--report-dir", str(tmp_path / "rep")]) == 0
    out = capsys.readouterr().out
    assert "Far (paper) - near: AUC" in out and "\nnear " in out
    for bad, message in ((f"near,Near={tmp_path / 'near'}", "is named twice"),
                         (f"X={tmp_path / 'near'},X={tmp_path / 'published' / 'far'}", "given one name: X"),
                         ("X=nowhere", "no results for tracker 'X': nowhere is not a folder")):
        assert cli.main(["report", str(tmp_path), "--root", str(tmp_path), "--trackers", bad,
                         "--report-dir", str(tmp_path / "rep")]) == 2
        assert message in capsys.readouterr().err
    assert cli.main(["compare", f"mine={tmp_path / 'near'}", named, "--root", str(tmp_path)]) == 0
    assert "AUC       mine " in capsys.readouterr().out


def test_tre_pools_the_frames_of_a_sequences_runs_as_perfplot_does(tmp_path):
    """A sequence's TRE score: successes summed over its 20 runs / their frames (perfPlot.m),
    brute-forced here from the per-frame overlaps of each run; sequences then weigh alike."""
    from dcfkit.experiments.otb import tre_runs

    rng = np.random.default_rng(3)
    cv2.imwrite(str(tmp_path / "0.jpg"), np.zeros((100, 120, 3), np.uint8))  # TRE starts are checked against its size
    seqs = [Sequence(name, tuple(tmp_path / f"{k}.jpg" for k in range(n)),
                     np.column_stack([np.arange(n) + 5.0, np.full(n, 5.0), np.full(n, 20.0), np.full(n, 30.0)]))
            for name, n in (("long", 60), ("short", 30))]
    results, by_hand = {}, {}
    for seq in seqs:
        successes, frames = np.zeros(21), 0
        for run in tre_runs(seq):
            boxes = run.ground_truth + rng.normal(0, 4, run.ground_truth.shape) * [1, 1, 0, 0]
            boxes[0] = run.ground_truth[0]  # frame 1 of each run is scored with the ground truth
            results[run.name] = boxes
            overlap = np.array([metrics_overlap(b, g) for b, g in zip(boxes, run.ground_truth)])
            successes += (overlap[:, None] > np.linspace(0, 1, 21)[None, :]).sum(axis=0)
            frames += len(run)
        by_hand[seq.name] = (successes / frames).mean()
    scores = evaluate({"t": results}, seqs, protocol="otb", experiment="tre")
    rows = {r["sequence"]: r for r in scores.per_sequence}
    assert rows["long"]["auc"] == pytest.approx(by_hand["long"])
    assert rows["short"]["auc"] == pytest.approx(by_hand["short"])
    assert scores.overall[0]["auc"] == pytest.approx((by_hand["long"] + by_hand["short"]) / 2)
    assert scores.settings["experiment"] == "tre"
    assert len(tre_runs(seqs[1])) == 19  # 30 frames: E = 11, 1:11/19:11 has 18 values, then 11
    del results["short_005"]  # one run missing: the sequence lacks a result
    partial = evaluate({"t": results}, seqs, protocol="otb", experiment="tre", missing="skip")
    assert partial.settings["left_out"] == {"short": ["t"]}


def metrics_overlap(box, gt) -> float:
    """calcRectInt.m's overlap of two 1-based-pixel boxes (x, y, w, h), by hand."""
    left, top = max(box[0], gt[0]), max(box[1], gt[1])
    right, bottom = min(box[0] + box[2] - 1, gt[0] + gt[2] - 1), min(box[1] + box[3] - 1, gt[1] + gt[3] - 1)
    inter = max(0.0, right - left + 1) * max(0.0, bottom - top + 1)
    return inter / (box[2] * box[3] + gt[2] * gt[3] - inter)


def test_the_statistics_say_which_sequences_a_non_finite_score_left_out():
    """Two one-frame sequences score NaN under GOT-10k (frame 1 is left out): the statistics are
    over the other three and say so, naming the two."""
    one_frame = [Sequence(name=n, frames=(Path("00000.jpg"),), ground_truth=GT[:1].copy(), attributes={},
                          dataset="test") for n in ("x", "y")]
    results = {t: {**r, "x": GT[:1].copy(), "y": GT[:1].copy()} for t, r in RESULTS.items()}
    st = evaluate(results, SEQUENCES[:3] + one_frame, protocol="got10k").statistics
    assert st.sequences == 5 and st.non_finite["far"] == {"ao": ["x", "y"], "precision": ["x", "y"]}
    assert {m["ao"].n for m in st.means.values()} == {3}
    lines = statistics_lines(st)
    assert lines[0].startswith("statistics over 3 of the 5 sequences: ")
    assert ("  left out of every mean and difference: a non-finite score (no frame counted) in 2 sequences (x, y)"
            in lines)
    st = dataclasses.replace(st, non_finite={"far": {"ao": ["x"]}})  # one tracker's one score: named as such
    assert statistics_lines(st)[0].startswith("statistics over 5 sequences: ")
    assert "  left out of far's AO: a non-finite score (no frame counted) in 1 sequence (x)" in statistics_lines(st)
