"""--max-frames: smoke runs of eval and ablate on each sequence's first frames, whose results
are never taken for a full run's."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from test_ablation import write_otb

from dcfkit import cli
from dcfkit.datasets import DatasetError, Sequence, load_dataset


@pytest.fixture
def data(tmp_path):
    for i, name in enumerate(("seqA", "seqB")):
        write_otb(tmp_path / "data", name, seed=i)
    return tmp_path / "data"


def test_a_smoke_run_tracks_the_first_frames_and_a_full_run_recomputes(data, tmp_path, capsys):
    n = len(load_dataset("otb", data)[0])
    base = ["eval", "kcf", "--dataset", "otb", "--root", str(data), "--out", str(tmp_path / "out"), "--no-progress"]
    assert cli.main(base + ["--max-frames", "4"]) == 0
    assert (tmp_path / "out" / "kcf" / "seqA.txt").read_text().count("\n") == 4
    assert json.loads((tmp_path / "out" / "kcf" / "seqA.json").read_text())["frames"] == 4
    assert cli.main(base + ["--max-frames", "4"]) == 0 and "0 run, 2 already done" in capsys.readouterr().out
    assert cli.main(["report", str(tmp_path / "out"), "--dataset", "otb", "--root", str(data), "--max-frames", "4"]) == 0
    capsys.readouterr()
    scored = json.loads((tmp_path / "out_report" / "report.json").read_text())["per_sequence"]
    assert [(r["sequence"], r["frames"]) for r in scored] == [("seqA", 4), ("seqB", 4)]
    assert cli.main(base) == 0 and "2 run, 0 already done" in capsys.readouterr().out  # cut results: not full ones
    assert (tmp_path / "out" / "kcf" / "seqA.txt").read_text().count("\n") == n


def test_an_ablation_smoke_run(data, tmp_path, capsys):
    (tmp_path / "spec.yaml").write_text("name: smoke\ndataset: {name: otb, root: data}\nvariants: {k: kcf}\n")
    assert cli.main(["ablate", str(tmp_path / "spec.yaml"), "--out", str(tmp_path / "out"), "--max-frames", "3",
                     "--no-progress", "--jobs", "1"]) == 0
    (sidecar,) = [p for p in (tmp_path / "out").rglob("seqA.json")]
    assert sidecar == tmp_path / "out" / "k" / "seqA.json"  # the variant's folder, as eval's tracker folders
    assert json.loads(sidecar.read_text())["frames"] == 3


@pytest.mark.parametrize("bad", ["0", "-2", "x", "1.5"])
def test_a_frame_limit_is_a_positive_whole_number(data, tmp_path, capsys, bad):
    with pytest.raises(SystemExit):
        cli.main(["eval", "kcf", "--dataset", "otb", "--root", str(data), "--out", str(tmp_path), "--max-frames", bad])
    assert "--max-frames: expected" in capsys.readouterr().err


def test_head_keeps_a_sequence_whole_or_cuts_it():
    seq = Sequence("x", (Path("a.jpg"), Path("b.jpg"), Path("c.jpg")), np.ones((3, 4)), {}, "t")
    assert seq.head(None) is seq and seq.head(len(seq) + 5) is seq
    cut = seq.head(2)
    assert len(cut) == 2 and cut.frames == seq.frames[:2] and (cut.ground_truth == seq.ground_truth[:2]).all()
    with pytest.raises(DatasetError, match="at least 1 frame"):
        seq.head(0)


def test_a_smoke_run_reported_without_its_cut_says_so_once(data, tmp_path, capsys):
    """dcfkit <= 0.9 warned once per result file, then said to report fewer trackers."""
    base = ["--dataset", "otb", "--root", str(data), "--no-progress"]
    assert cli.main(["eval", "kcf", "dsst", "--out", str(tmp_path / "out"), "--max-frames", "4", *base]) == 0
    capsys.readouterr()
    report = ["report", str(tmp_path / "out"), "--dataset", "otb", "--root", str(data)]
    for flag, said in (([], "no --max-frames"), (["--max-frames", "3"], "--max-frames 3")):
        assert cli.main(report + flag) == 2
        err = capsys.readouterr().err
        assert err.strip().splitlines() == [
            f"dcfkit report: error: the results of dsst, kcf in {tmp_path / 'out'} were cut by --max-frames 4 (their "
            f"runs of seqA, seqB hold at most 4 frames) and this report has {said}: report them with --max-frames 4"]
    assert cli.main(report + ["--max-frames", "4", "--format", "csv"]) == 0
    assert capsys.readouterr().out.splitlines()[0].endswith(",protocol,experiment,max_frames")
    record = json.loads((tmp_path / "out_report" / "report.json").read_text())
    assert record["settings"]["max_frames"] == 4
    cut = "a smoke run: each sequence cut to its first 4 frames (--max-frames 4)"
    for name in ("overall.txt", "overall.md", "statistics.txt", "per_sequence.txt"):
        assert cut in (tmp_path / "out_report" / name).read_text().splitlines()[0], name
    assert "(-{}-max-frames 4)" in (tmp_path / "out_report" / "overall.tex").read_text()
    assert (tmp_path / "out_report" / "per_sequence.csv").read_text().splitlines()[1].endswith(",ope,4")


def test_whole_runs_reported_with_a_cut_and_results_of_another_dataset_are_named(data, tmp_path, capsys):
    base = ["--dataset", "otb", "--no-progress"]
    assert cli.main(["eval", "kcf", "--out", str(tmp_path / "out"), "--root", str(data), *base]) == 0
    capsys.readouterr()
    assert cli.main(["report", str(tmp_path / "out"), "--root", str(data), "--max-frames", "4", *base[:2]]) == 2
    assert ("dcfkit report: error: the results of kcf in " in (err := capsys.readouterr().err)
            and "are whole runs (seqA, seqB: longer than this report's --max-frames 4 leaves): report them "
                "without --max-frames" in err)
    other = tmp_path / "other"
    write_otb(other, "seqX", seed=5)
    for trackers in ([], ["--trackers", "kcf"]):
        assert cli.main(["report", str(tmp_path / "out"), "--root", str(other), *base[:2], *trackers]) == 2
        err = capsys.readouterr().err
        assert err.strip().splitlines() == [
            f"dcfkit report: error: the results in {tmp_path / 'out'} are of other sequences than the 1 scored here "
            f"(seqX): they are of seqA, seqB; report them on the dataset they were run on (--dataset, --root, "
            f"--sequences)"]
