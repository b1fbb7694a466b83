"""A stored run stands only for the data and the frames it was made on: eval reruns it after any
ground-truth change, report leaves it out, and a --max-frames smoke run never replaces a longer
run (issue 37, the attacker's review of the experiments)."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from test_ablation import write_otb
from test_evaluation import Counter
from test_experiment_runs import seqs  # noqa: F401  (a fixture: two 25-frame sequences)

from dcfkit import cli
from dcfkit.datasets import DatasetError
from dcfkit.running.evaluation import experiment_runs, results_folder, run_one_pass
from dcfkit.store.results import load_results

CONFIG = {"name": "drift", "drift": 1.0}


def moved(seq, row, dx=40.0):
    """``seq`` with its ground truth's x moved by ``dx`` from 0-based ``row`` on (a corrected annotation)."""
    gt = seq.ground_truth.copy()
    gt[row:, 0] += dx
    return dataclasses.replace(seq, ground_truth=gt)


@pytest.mark.parametrize("experiment", ["ope", "tre", "reset"])
def test_every_run_of_a_sequence_whose_later_ground_truth_changed_runs_again(tmp_path, seqs, experiment):  # noqa: F811
    run_one_pass(CONFIG, seqs, tmp_path, make_tracker=Counter(), progress=False, experiment=experiment)
    corrected = [moved(seqs[0], len(seqs[0]) - 1), seqs[1]]  # the last row only: frame 1 is as it was
    again = run_one_pass(CONFIG, corrected, tmp_path, make_tracker=Counter(), progress=False, experiment=experiment)
    assert again["done"] == [r.name for r in experiment_runs(corrected[:1], experiment)]
    assert again["skipped"] == [r.name for r in experiment_runs(corrected[1:], experiment)]


@pytest.mark.parametrize("row", [0, 5])
def test_report_leaves_out_a_result_made_before_the_ground_truth_changed(tmp_path, seqs, row, caplog):  # noqa: F811
    run_one_pass(CONFIG, seqs, tmp_path, make_tracker=Counter(), progress=False)
    corrected = [moved(seqs[0], row, dx=1.0), seqs[1]]
    with caplog.at_level("WARNING"):
        assert sorted(load_results(tmp_path, "drift", corrected)) == ["b"]
    reason = "started from the box" if row == 0 else "was made on other data"
    assert f"a.json: its run {reason}" in caplog.text and "left out; run it again to recompute 'a'" in caplog.text
    assert sorted(load_results(tmp_path, "drift", seqs)) == ["a", "b"]  # nothing was removed


@pytest.mark.parametrize("experiment", ["ope", "tre", "sre", "reset"])
def test_a_smoke_run_never_replaces_longer_results(tmp_path, seqs, experiment, caplog):  # noqa: F811
    run_one_pass(CONFIG, seqs, tmp_path, make_tracker=Counter(), progress=False, experiment=experiment)
    folder = results_folder(tmp_path, CONFIG, experiment)
    before = {p.name: p.read_bytes() for p in folder.iterdir() if p.is_file()}
    cut = [s.head(22) for s in seqs]
    with pytest.raises(DatasetError, match=r"_?\w*\.txt holds an intact run of \d+ frames and this run of '\w+' has "
                                           r"\d+ \(--max-frames\): it is not replaced; write this run to another"):
        run_one_pass(CONFIG, cut, tmp_path, make_tracker=Counter(), progress=False, experiment=experiment)
    assert {p.name: p.read_bytes() for p in folder.iterdir() if p.is_file()} == before
    assert "damaged" not in caplog.text


def test_a_full_run_replaces_a_smoke_runs_results_and_says_why(tmp_path, seqs, caplog):  # noqa: F811
    run_one_pass(CONFIG, [s.head(5) for s in seqs], tmp_path, make_tracker=Counter(), progress=False)
    with caplog.at_level("WARNING"):
        assert run_one_pass(CONFIG, seqs, tmp_path, make_tracker=Counter(), progress=False)["done"] == ["a", "b"]
    assert ("replacing 2 result(s) of fewer frames (a --max-frames smoke run's, or the sequence has grown): a, b"
            in caplog.text)
    assert "damaged" not in caplog.text and "other data" not in caplog.text


def test_eval_max_frames_into_full_results_is_one_line_and_keeps_them(tmp_path, capsys):
    write_otb(tmp_path / "data", "seqA", seed=0, n_frames=8)
    base = ["eval", "kcf", "--dataset", "otb", "--root", str(tmp_path / "data"), "--out", str(tmp_path / "out"),
            "--no-progress"]
    assert cli.main(base) == 0
    full = (tmp_path / "out" / "kcf" / "seqA.txt").read_bytes()
    capsys.readouterr()
    assert cli.main(base + ["--max-frames", "5"]) != 0
    err = capsys.readouterr().err.strip()
    assert "seqA.txt holds an intact run of 8 frames and this run of 'seqA' has 5" in err and "\n" not in err
    assert (tmp_path / "out" / "kcf" / "seqA.txt").read_bytes() == full


def test_a_reset_run_without_frame_1_ground_truth_resumes_and_is_scored(tmp_path, seqs, caplog):  # noqa: F811
    """Its sidecar's first box is NaN, which equals no NaN: it was run again each time, and left out."""
    gt = seqs[0].ground_truth.copy()
    gt[:2] = np.nan
    late = dataclasses.replace(seqs[0], ground_truth=gt)
    run_one_pass(CONFIG, [late], tmp_path, make_tracker=Counter(), progress=False, experiment="reset")
    again = run_one_pass(CONFIG, [late], tmp_path, make_tracker=Counter(), progress=False, experiment="reset")
    assert again["skipped"] == ["a"] and again["done"] == []
    assert list(load_results(tmp_path / "drift", "reset", [late])) == ["a"] and "left out" not in caplog.text


def test_compare_leaves_out_a_result_made_before_the_ground_truth_changed(tmp_path, seqs, caplog):  # noqa: F811
    from dcfkit.analysis.compare import compare_folders

    for out in ("ours", "theirs"):
        run_one_pass(CONFIG, seqs, tmp_path / out, make_tracker=Counter(), progress=False)
    corrected = [moved(seqs[0], 5, dx=1.0), seqs[1]]
    with caplog.at_level("WARNING"):
        found = compare_folders(tmp_path / "ours" / "drift", tmp_path / "theirs" / "drift", corrected)
    assert [row["sequence"] for row in found["rows"]] == ["b"] and found["left_out"]["damaged"] == ["a"]
    assert "a.json: its run was made on other data" in caplog.text


@pytest.mark.parametrize("experiment", ["ope", "tre"])
def test_a_sequence_shortened_or_corrected_in_its_folder_runs_again(tmp_path, seqs, experiment):  # noqa: F811
    """Only a smoke run's cut sequence is refused: one shortened in its folder (or a TRE run that a
    corrected row made shorter) is other data, recomputed."""
    run_one_pass(CONFIG, seqs, tmp_path, make_tracker=Counter(), progress=False, experiment=experiment)
    short = dataclasses.replace(seqs[0], frames=seqs[0].frames[:22], ground_truth=seqs[0].ground_truth[:22])
    again = run_one_pass(CONFIG, [short, seqs[1]], tmp_path, make_tracker=Counter(), progress=False,
                         experiment=experiment)
    assert again["done"] == [r.name for r in experiment_runs([short], experiment)]
