"""A new experiment is added where docs/architecture.md's "Where to add" says: an
:class:`~dcfkit.experiments.base.Experiment` and an entry in ``EXPERIMENTS``, nothing else. This
toy one has runs of its own (each sequence's two halves) and a loop of its own (it counts the
frames it tracked and records them); eval, report and ablate take it by name."""
from __future__ import annotations

import dataclasses
import json

import pytest
from test_ablation import write_otb, write_spec

from dcfkit import cli
from dcfkit.datasets import Sequence
from dcfkit.experiments import EXPERIMENTS, Experiment
from dcfkit.experiments.starts import Plan

N = 24


def halves(seq: Sequence) -> Plan:
    """Two runs: frames 1..N/2 from frame 1's ground truth, and the rest from the middle frame's."""
    middle = len(seq) // 2
    runs = [dataclasses.replace(seq, name=f"{seq.name}_{k}", frames=seq.frames[a:b], ground_truth=seq.ground_truth[a:b],
                                start_box=None) for k, (a, b) in enumerate(((0, middle), (middle, len(seq))), 1)]
    return Plan(runs, {})


@dataclasses.dataclass(frozen=True)
class Halves(Experiment):
    """Each half tracked by the base loop, and the count of frames recorded in the sidecar."""

    def track(self, tracker, make_tracker, run, read, tick=None):
        tracked = super().track(tracker, make_tracker, run, read, tick)
        COUNTED.append(len(tracked.boxes))
        return tracked

    def record(self, result) -> dict:
        return {"halves": {"frames": len(result.boxes)}}


COUNTED: list[int] = []  # the frames of each run the toy loop tracked


@pytest.fixture
def toy(monkeypatch):
    COUNTED.clear()
    experiment = Halves("halves", "each half of a sequence", "a test", halves, "halves", pooled=True)
    monkeypatch.setitem(EXPERIMENTS, "halves", experiment)
    return experiment


def test_a_toy_experiment_runs_scores_and_reports_through_the_commands(tmp_path, capsys, toy):
    root, out = tmp_path / "data", tmp_path / "out"
    for i, name in enumerate(("seqA", "seqB")):
        write_otb(root, name, seed=i, n_frames=N)
    data = ["--dataset", "otb", "--root", str(root)]
    assert cli.main(["eval", "kcf", "dsst", *data, "--out", str(out), "--experiment", "halves", "--no-progress"]) == 0
    printed = capsys.readouterr().out
    assert f"-> {out / 'kcf' / 'halves'}" in printed and "HALVES runs pooled per sequence" in printed
    assert sorted(COUNTED) == [N // 2] * 8  # its own loop ran: 2 trackers x 2 sequences x 2 halves
    sidecar = json.loads((out / "kcf" / "halves" / "seqB_2.json").read_text())
    assert sidecar["halves"] == {"frames": N // 2} and sidecar["frames"] == N // 2

    assert cli.main(["report", str(out), *data, "--experiment", "halves", "--html",
                     "--report-dir", str(tmp_path / "report")]) == 0
    assert capsys.readouterr().out.startswith("experiment HALVES (each half of a sequence; a test), each sequence's "
                                              "runs pooled")
    record = json.loads((tmp_path / "report" / "report.json").read_text())
    assert {r["tracker"] for r in record["overall"]} == {"kcf", "dsst"} and record["experiment"]["name"] == "halves"
    assert "dcfkit report (HALVES)" in (tmp_path / "report" / "report.html").read_text()

    spec = write_spec(tmp_path / "spec.yaml", f"""
name: toy
dataset: {{name: otb, root: {root}}}
experiment: halves
variants:
  KCF: {{config: kcf}}
""")
    assert cli.main(["ablate", str(spec), "--out", str(tmp_path / "ablation"), "--jobs", "1", "--no-progress"]) == 0
    assert json.loads((tmp_path / "ablation" / "summary.json").read_text())["experiment"] == "halves"
