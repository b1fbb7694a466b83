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
    (sidecar,) = [p for p in (tmp_path / "out" / "jobs").rglob("seqA.json")]
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

