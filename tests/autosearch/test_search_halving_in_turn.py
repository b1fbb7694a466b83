"""Successive halving with the experiments in turn (issue 42): a unit is a sequence under one
experiment, OPE on every sequence first, so a trial reaches the costly TRE only if OPE keeps it.
Checked against the plain scoring of the same runs, a hand-computed step, the runs on
disk and a resume."""
from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from test_ablation import write_otb
from test_search_halving import SPEC, STUDIES, trials

from dcfkit import cli
from dcfkit.autosearch import Search, load_search_spec
from dcfkit.autosearch.halving import Halving
from dcfkit.autosearch.records import complete
from dcfkit.errors import ConfigError
from dcfkit.experiments import runs_by_sequence

pytest.importorskip("optuna")

BOTH = SPEC.replace("folds: 2\n", "folds: 2\nexperiments: [ope, tre]\n").replace("trials: 6", "trials: 5")
IN_TURN = "halving: {min_sequences: 1, reduction_factor: 2, experiments: in_turn}\n"


@pytest.fixture(scope="module")
def searches(tmp_path_factory) -> Path:
    """Four synthetic sequences of 21 frames (``data``: TRE's shortest) and an OPE + TRE search
    with :data:`IN_TURN` run to its end (``in_turn``); ``plain.yaml`` is its spec without halving."""
    folder = tmp_path_factory.mktemp("in_turn")
    for i in range(4):
        write_otb(folder / "data", f"seq{i}", seed=i, n_frames=21)
    (folder / "plain.yaml").write_text(BOTH, encoding="utf-8")
    (folder / "in_turn.yaml").write_text(BOTH + IN_TURN, encoding="utf-8")
    lines: list[str] = []
    Search(load_search_spec(folder / "in_turn.yaml"), folder / "in_turn", {"jobs": 1}, report=lines.append).run()
    (folder / "printed.txt").write_text("\n".join(lines), encoding="utf-8")
    return folder


def search(folder: Path, spec: str = "in_turn") -> Search:
    """A search of ``spec`` writing to ``folder / "in_turn"``: the plain spec reuses its runs."""
    return Search(load_search_spec(folder / f"{spec}.yaml"), folder / "in_turn", {"jobs": 1})


def test_units_take_each_experiment_in_turn_and_the_rungs_count_them():
    order, halving = ["b", "a", "c"], Halving(1, 2, "in_turn")
    assert halving.units(order, ("ope", "tre")) == [(("ope",), "b"), (("ope",), "a"), (("ope",), "c"),
                                                    (("tre",), "b"), (("tre",), "a"), (("tre",), "c")]
    assert Halving(1, 2).units(order, ("ope", "tre")) == [(("ope", "tre"), n) for n in order]
    assert halving.rungs(6) == [1, 2, 4, 6]
    # pruned at 4: every sequence under OPE, the first under TRE: only that one is complete
    assert complete(halving.units(order, ("ope", "tre"))[:4], ("ope", "tre")) == ["b"]
    assert complete(halving.units(order, ("ope", "tre"))[:3], ("ope", "tre")) == []


def test_each_step_is_the_mean_auc_of_the_units_reached_by_hand(searches):
    s = search(searches)
    checked = 0
    for study in STUDIES:
        units = s.units(study)
        for rec in trials(searches / "in_turn", study):
            by = rec["by_experiment"]
            for count, value in rec["steps"]:
                aucs = [by[exps[0]][n]["auc"] for exps, n in units[:count]]
                assert value == pytest.approx(np.mean(aucs), abs=1e-15)
                checked += 1
            reached = units[:rec["steps"][-1][0]]
            for e in ("ope", "tre"):
                assert sorted(by[e]) == sorted(n for exps, n in reached if exps == (e,))
            complete = [n for n in s.order(study) if n in by["ope"] and n in by["tre"]]
            assert sorted(rec["scores"]) == sorted(complete)
            for n in complete:
                assert rec["scores"][n]["auc"] == (by["ope"][n]["auc"] + by["tre"][n]["auc"]) / 2
    assert checked > 20


def test_a_trial_pruned_under_ope_never_runs_tre(searches):
    """The saving is real: no TRE run of a config whose every trial OPE pruned is on disk."""
    s = search(searches)
    early = [r for study in STUDIES for r in trials(searches / "in_turn", study)
             if r["pruned"] and r["steps"][-1][0] <= len(s.training(study))]
    assert early, "the fixture should prune some trial under OPE"
    untried = 0  # configs no trial took to TRE
    for rec in early:
        assert rec["scores"] == {} and rec["value"] is None and rec["by_experiment"]["tre"] == {}
        if not any(r["key"] == rec["key"] and r["steps"][-1][0] > len(s.training(study))
                   for study in STUDIES for r in trials(searches / "in_turn", study)):
            untried += 1
            tre = searches / "in_turn" / "runs" / rec["key"] / "tre"
            assert not tre.exists() or not any(tre.iterdir())
            assert any((searches / "in_turn" / "runs" / rec["key"]).glob("*.txt"))  # its OPE runs
    assert untried
    summary = json.loads((searches / "in_turn/summary.json").read_text())
    saved = summary["halving"]["studies"]["all"]
    seqs = list(s.evaluator.sequences.values())
    # every frame of OPE and TRE, but TRE's runs from frame 1: copies of OPE's (docs/evaluation.md)
    tre = runs_by_sequence(seqs, "tre")
    frames = sum(len(seq) + sum(len(run) for run in tre[seq.name] if run.frames[0] != seq.frames[0]) for seq in seqs)
    assert frames < sum(len(seq) + sum(map(len, tre[seq.name])) for seq in seqs)
    assert saved["frames_unpruned"] == len(trials(searches / "in_turn", "all")) * frames
    assert saved["frames"] < saved["frames_unpruned"]
    assert "experiments in turn" in (searches / "in_turn/summary.md").read_text()
    assert "mean AUC" in (printed := (searches / "printed.txt").read_text())
    assert f"pruned after {early[0]['steps'][-1][0]} (sequence, experiment) pair" in printed


def test_a_trial_left_unpruned_scores_as_in_the_plain_search(searches):
    """A trial that reaches the last rung has the value and scores a search without halving
    gives its config (from the same runs), bit for bit."""
    halved, plain, complete = search(searches), search(searches, "plain"), 0
    for study in STUDIES:
        records = trials(searches / "in_turn", study)
        assert not records[0]["pruned"]  # the base: the first at every rung
        for rec in (r for r in records if not r["pruned"]):
            complete += 1
            expected = plain._scored(rec["config"], halved.training(study), study, None)
            assert (rec["value"], rec["scores"]) == (expected["value"], expected["scores"])
    assert complete > len(STUDIES)


def test_a_resume_runs_nothing_and_an_edited_unit_score_is_redone(searches, tmp_path, caplog):
    out = tmp_path / "in_turn"
    shutil.copytree(searches / "in_turn", out)
    before = {p: p.read_bytes() for p in out.glob("trials/*/*.json")}
    runs = {p: p.stat().st_mtime_ns for p in out.glob("runs/**/*.txt")}
    spec = tmp_path / "in_turn.yaml"
    spec.write_text(BOTH.replace("root: data", f"root: {searches / 'data'}") + IN_TURN, encoding="utf-8")
    assert cli.main(["search", str(spec), "--out", str(out), "--jobs", "1"]) == 0
    assert {p: p.read_bytes() for p in out.glob("trials/*/*.json")} == before
    assert {p: p.stat().st_mtime_ns for p in out.glob("runs/**/*.txt")} == runs  # none rewritten
    s = Search(load_search_spec(spec), out, {"jobs": 1})
    rec = trials(out, "fold1")[1]
    path = out / "trials" / "fold1" / "0001.json"
    name = s.order("fold1")[0]
    edited = json.loads(json.dumps(rec))
    edited["by_experiment"]["ope"][name]["auc"] = 0.123
    path.write_text(json.dumps(edited), encoding="utf-8")
    records, _ = s.recorded("fold1")
    assert len(records) == 1
    assert "is not the mean AUC of the scores of the first 1 units" in caplog.text and str(path) in caplog.text
    assert s.run_study("fold1")[1] == rec


def test_a_score_row_missing_a_key_is_a_fault_not_a_crash():
    from dcfkit.autosearch.records import by_experiment_fault, scores_fault

    units = [(("ope",), "a"), (("tre",), "a")]
    row = {"auc": 0.5, "precision": 0.5}
    assert by_experiment_fault({"scores": {"a": row}, "by_experiment": {"ope": {"a": row}, "tre": {"a": {"auc": 0.5}}}},
                               units, ("ope", "tre")) == "by_experiment: expected {auc, precision} numbers or null " \
                                                        "for each sequence"
    assert scores_fault({"scores": {"a": {"precision": 0.5}}, "value": 0.5}, ["a"]) == \
        "scores: expected {auc, precision} numbers or null for each sequence"


def test_the_experiments_key_is_checked_and_a_015_record_resumes_as_together(searches, tmp_path):
    (tmp_path / "s.yaml").write_text(BOTH + IN_TURN.replace("in_turn", "both"), encoding="utf-8")
    with pytest.raises(ConfigError, match="halving.experiments: expected together or in_turn, got 'both'") as err:
        load_search_spec(tmp_path / "s.yaml")
    assert str(tmp_path / "s.yaml") in str(err.value)
    # dcfkit 0.15.0 recorded halving without experiments: it reads as together (the version in
    # every run key refuses 0.15.0's searches anyway; this keeps the halving check from misnaming it)
    out = tmp_path / "halved"
    spec = tmp_path / "halved.yaml"
    spec.write_text(BOTH.replace("root: data", f"root: {searches / 'data'}").replace("trials: 5", "trials: 1")
                    + "halving: {min_sequences: 1, reduction_factor: 2}\n", encoding="utf-8")
    out.mkdir()
    s = Search(load_search_spec(spec), out, {"jobs": 1})
    s.check_record()
    record = json.loads((out / "search.json").read_text())
    assert record["fingerprint"]["halving"].pop("experiments") == "together"
    (out / "search.json").write_text(json.dumps(record), encoding="utf-8")
    Search(load_search_spec(spec), out, {"jobs": 1}).check_record()  # no refusal


def test_the_benchmark_replays_a_plain_search_in_turn_as_the_halved_search_ran(searches, tmp_path):
    """The plain search's first trials are the halved one's (random startup trials, one seed):
    replayed in turn through the same halving they are pruned as the halved search pruned them."""
    plain = tmp_path / "plain"
    plain.mkdir()
    for folder in ("runs", "baselines"):  # run keys name config and version: the runs are shared
        (plain / folder).symlink_to(searches / "in_turn" / folder)
    (tmp_path / "plain.yaml").write_text(BOTH.replace("root: data", f"root: {searches / 'data'}")
                                         .replace("trials: 5", "trials: 3"), encoding="utf-8")
    Search(load_search_spec(tmp_path / "plain.yaml"), plain, {"jobs": 1}).run()
    script = Path(__file__).resolve().parents[2] / "benchmarks" / "halving.py"
    done = subprocess.run([sys.executable, str(script), str(tmp_path / "plain.yaml"), str(plain), "--settings", "1x2",
                           "--in-turn"], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    pruned = sum(r["pruned"] for study in STUDIES for r in trials(searches / "in_turn", study)[:3])
    assert "experiments: in_turn" in done.stdout
    assert f"all studies: {pruned} of 9 trials pruned" in done.stdout


def test_the_audit_completes_the_furthest_pruned_trials_and_sets_them_against_the_best(searches, tmp_path):
    out = tmp_path / "in_turn"
    shutil.copytree(searches / "in_turn", out)  # the audit's runs must not reach the fixture's folder
    spec = tmp_path / "in_turn.yaml"
    spec.write_text(BOTH.replace("root: data", f"root: {searches / 'data'}") + IN_TURN, encoding="utf-8")
    script = Path(__file__).resolve().parents[2] / "benchmarks" / "halving_audit.py"
    done = subprocess.run([sys.executable, str(script), str(spec), str(out), "--top", "1"],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    search = Search(load_search_spec(spec), out, {"jobs": 1})
    rows = [line.strip("| ").split(" | ") for line in done.stdout.splitlines() if line.startswith(("| fold", "| all"))]
    assert [r[0] for r in rows] == [s for s in STUDIES if any(t["pruned"] for t in trials(out, s))]
    for study, trial, _, _, completed, best, winner in rows:
        rec, names = trials(out, study)[int(trial)], search.training(study)
        expected = search._scored(rec["config"], names, study, None)["value"]  # plain scoring: its runs are made
        top = max(t["value"] for t in trials(out, study) if t["value"] is not None)
        assert completed == f"{expected:.4f}" and best.endswith(f", {top:.4f}")
        assert winner == ("yes" if expected > top else "no")


def test_status_says_where_the_search_stands_and_runs_nothing(searches, tmp_path, capsys):
    out = tmp_path / "in_turn"
    shutil.copytree(searches / "in_turn", out)
    spec = tmp_path / "in_turn.yaml"
    spec.write_text(BOTH.replace("root: data", f"root: {searches / 'data'}") + IN_TURN, encoding="utf-8")
    command = ["search", str(spec), "--out", str(out), "--status"]
    assert cli.main(command) == 0
    printed = capsys.readouterr().out.splitlines()
    summary = json.loads((out / "summary.json").read_text())
    final = trials(out, "all")[summary["final"]["trial"]]
    pruned = sum(r["pruned"] for r in trials(out, "all"))
    assert printed[0] == f"search halved under {out}: 3 of 3 studies complete, 15 of 15 trials recorded"
    assert printed[3] == (f"  all: 5 of 5 trials ({pruned} pruned); best trial {final['number']}, mean AUC "
                          f"{final['value']:.4f} on 4 sequences")
    assert printed[-1] == "summary.md: written"
    (out / "trials" / "all" / "0004.json").unlink()
    before = {p: p.stat().st_mtime_ns for p in out.rglob("*")}
    assert cli.main(command) == 0
    printed = capsys.readouterr().out.splitlines()
    assert printed[0].endswith("2 of 3 studies complete, 14 of 15 trials recorded")
    assert printed[3].startswith("  all: 4 of 5 trials")
    assert printed[-1] == "summary.md: not yet: it is written when the studies it runs are complete"
    assert {p: p.stat().st_mtime_ns for p in out.rglob("*")} == before  # nothing run, nothing written
    assert cli.main(["search", str(spec), "--out", str(tmp_path / "none"), "--status"]) != 0
    assert "no search is recorded under" in capsys.readouterr().err
