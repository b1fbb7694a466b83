"""How a run's speed was measured: recorded in its sidecar, and fps shown as a score only for
runs timed alone (dcfkit.store.timing)."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from test_evaluation import CONFIG, Counter, make_drift, seqs  # noqa: F401  (the fixture)

from dcfkit import cli
from dcfkit.analysis import report
from dcfkit.analysis.scoring import evaluate
from dcfkit.datasets import Sequence
from dcfkit.running import runner
from dcfkit.running.evaluation import run_one_pass
from dcfkit.store.results import load_results
from dcfkit.store.timing import ADVICE, fps_note


@pytest.fixture
def inline_pool(monkeypatch):
    """A pool of two workers on a machine of four cores, its calls made in this process (no
    processes to start): what each run records is what a real pool's would."""
    def run_pool(calls, jobs, on_result, on_crash):
        for key, (fn, *args) in calls.items():
            on_result(key, fn(*args))

    monkeypatch.setattr(runner, "run_pool", run_pool)
    monkeypatch.setattr(runner, "worker_init", lambda *args: None)  # this process keeps its threads
    monkeypatch.setattr(runner, "_worker_ready", False)
    monkeypatch.setattr(runner, "usable_cores", lambda: 4)


def sidecars(folder) -> dict:
    return {p.stem: json.loads(p.read_text()) for p in folder.glob("*.json")}


def test_each_run_records_whether_it_was_timed_alone(tmp_path, seqs, inline_pool):  # noqa: F811
    run_one_pass(CONFIG, seqs, tmp_path / "alone", make_tracker=Counter(), progress=False)
    run_one_pass(CONFIG, seqs, tmp_path / "pool", make_tracker=make_drift, jobs=2, progress=False)
    alone, pool = sidecars(tmp_path / "alone" / "drift"), sidecars(tmp_path / "pool" / "drift")
    assert {n: m["timing"] for n, m in alone.items()} == dict.fromkeys("abc", {"executor": "local", "workers": 1,
                                                                              "alone": True})
    assert {n: m["timing"] for n, m in pool.items()} == dict.fromkeys("abc", {"executor": "local", "workers": 2,
                                                                             "alone": False})
    assert all(m["fps"] > 0 for m in pool.values())  # measured, and kept in the sidecar
    assert load_results(tmp_path / "pool", "drift", seqs)["a"].timing == {"executor": "local", "workers": 2,
                                                                          "alone": False}


def test_fps_is_a_score_only_for_runs_timed_alone(tmp_path, seqs, inline_pool, monkeypatch):  # noqa: F811
    run_one_pass(CONFIG, seqs, tmp_path / "out", make_tracker=Counter(), progress=False)
    run_one_pass({**CONFIG, "name": "pooled"}, seqs, tmp_path / "out", make_tracker=make_drift, jobs=2,
                 progress=False)
    run_one_pass({**CONFIG, "name": "old"}, seqs, tmp_path / "out", make_tracker=Counter(), progress=False)
    for path in (tmp_path / "out" / "old").glob("*.json"):  # as dcfkit wrote sidecars before the record
        meta = json.loads(path.read_text())
        del meta["timing"]
        path.write_text(json.dumps(meta))
    ev = evaluate({t: load_results(tmp_path / "out", t, seqs) for t in ("drift", "pooled", "old")}, seqs)
    rows = {r["tracker"]: r for r in ev.overall}
    assert rows["drift"]["fps"] > 0 and rows["drift"]["fps_measured"] == "alone"
    assert rows["pooled"]["fps"] is None and rows["pooled"]["fps_measured"] == "shared"
    assert rows["old"]["fps"] is None and rows["old"]["fps_measured"] == "unknown"
    assert all((r["fps"] is None) == (r["tracker"] != "drift") for r in ev.per_sequence)
    note = ev.settings["fps_note"]
    assert note.startswith("fps not shown for pooled (measured with other runs sharing the CPU")
    assert "nor for old (not known how measured: results from before dcfkit recorded it)" in note
    assert note.endswith(ADVICE + ".") and "benchmarks/speed.py" in note and "--jobs 1" in note
    monkeypatch.setattr(report, "plot_curves", lambda *args, **kwargs: [])  # the tables are what is checked
    paths = report.write_report(tmp_path / "out", seqs, report_dir=tmp_path / "report")
    for name in ("overall.txt", "overall.md", "per_sequence.md"):
        assert (tmp_path / "report" / name).read_text().endswith(f"\n{note}\n"), name
    assert note not in (tmp_path / "report" / "overall.csv").read_text() and paths


def test_no_note_without_fps_left_out_and_a_record_dcfkit_did_not_write_is_unknown():
    rows = [{"tracker": "a", "fps_measured": "alone"}, {"tracker": "b", "fps_measured": None}]
    assert fps_note(rows) is None  # timed alone, or no times at all (imported boxes): nothing to say
    boxes = np.array([[1.0, 1.0, 5.0, 5.0]] * 3)
    seq = Sequence("s", (Path("1.jpg"), Path("2.jpg"), Path("3.jpg")), boxes, {}, "t")
    row = evaluate({"t": {"s": {"boxes": boxes, "fps": 10.0, "timing": {"alone": "yes"}}}}, [seq]).overall[0]
    assert row["fps"] is None and row["fps_measured"] == "unknown"  # a record dcfkit did not write


def test_an_ablation_in_a_pool_shows_no_fps_and_says_why(tmp_path, inline_pool, monkeypatch, capsys):
    from test_ablation import write_otb

    monkeypatch.setattr("dcfkit.ablation.summary.plot_curves", lambda *args, **kwargs: [])  # tables are checked

    for i, name in enumerate(("seqA", "seqB")):
        write_otb(tmp_path / "data", name, seed=i, n_frames=4)
    spec = tmp_path / "spec.yaml"
    spec.write_text("dataset: {name: otb, root: data}\nvariants: {k: {config: kcf}}\n")
    assert cli.main(["ablate", str(spec), "--out", str(tmp_path / "pool"), "--jobs", "2", "--no-progress"]) == 0
    printed = capsys.readouterr().out
    note = "fps not shown for k (measured with other runs sharing the CPU"
    assert note in printed and ADVICE in printed
    summary = (tmp_path / "pool" / "summary.md").read_text()
    assert note in summary and all(line.split("|")[4].strip() == "-" for line in summary.splitlines()
                                   if line.startswith("| k "))  # the fps column
    assert note in (tmp_path / "pool" / "report.html").read_text()
