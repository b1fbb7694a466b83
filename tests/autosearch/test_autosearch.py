"""dcfkit search: spec validation, folds, reproducible sampling, held-out scoring, resume.

Datasets are tiny synthetic sequences in the OTB layout (as the ablation tests write them)."""
from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from test_ablation import done_sidecars, write_otb

from dcfkit import cli
from dcfkit.analysis.scoring import evaluate
from dcfkit.autosearch import Search, load_search_spec, make_folds
from dcfkit.autosearch.study import sample
from dcfkit.config import load_config
from dcfkit.datasets import load_dataset
from dcfkit.errors import ConfigError, DcfkitError
from dcfkit.running.results import ResultStore

pytest.importorskip("optuna")

SPEC = """
name: tiny
dataset: {name: otb, root: data}
base: strcf
folds: 2
trials: 3
startup_trials: 2
baselines: {KCF: kcf}
space:
  label: {choice: {gaussian: {name: gaussian}, repressed: {name: distractor_repressed}}}
  label.mu: {float: [0.05, 1.0], log: true, when: {label: repressed}}
  regularizers.temporal.theta: {float: [4, 40], log: true}
  solver.iterations: {int: [1, 3]}
"""


@pytest.fixture
def data(tmp_path):
    root = tmp_path / "data"
    for i, name in enumerate(("seqA", "seqB", "seqC", "seqD")):
        write_otb(root, name, seed=i, n_frames=8)
    return root


def write(path: Path, text: str) -> Path:
    path.write_text(text, encoding="utf-8")
    return path


def test_folds_are_disjoint_cover_every_sequence_and_follow_the_seed():
    names = [f"s{i}" for i in range(11)]
    folds = make_folds(names, 4, seed=0)
    assert sorted(n for f in folds for n in f) == sorted(names)
    assert [len(f) for f in folds] == [3, 3, 3, 2]
    assert make_folds(list(reversed(names)), 4, seed=0) == folds  # the order given does not matter
    assert make_folds(names, 4, seed=1) != folds


def test_a_spec_is_resolved_when_read(tmp_path, data):
    spec = load_search_spec(write(tmp_path / "s.yaml", SPEC))
    assert [p.key for p in spec.parameters] == ["label", "label.mu", "regularizers.temporal.theta",
                                                "solver.iterations"]
    assert spec.experiments == ("ope",) and spec.folds == 2 and list(spec.baselines) == ["KCF"]
    config = spec.config({"label": "repressed", "label.mu": 0.5, "regularizers.temporal.theta": 7.0,
                          "solver.iterations": 2})
    assert config == load_config("strcf", {"label": {"name": "distractor_repressed"}, "label.mu": 0.5,
                                           "regularizers.temporal.theta": 7.0, "solver.iterations": 2})


@pytest.mark.parametrize("change, message", [
    ("solver.iterations: {int: [1, 3]}", None),
    ("solver.iterations: {int: [3, 1]}", r"space\.solver\.iterations\.int: expected \[low, high\] with low < high"),
    ("solver.iterations: {float: [1, 3], int: [1, 3]}", r"space\.solver\.iterations: give exactly one of"),
    ("solver.iteratons: {int: [1, 3]}", r"space\.solver\.iteratons: with the value 1: .*iteratons"),
    ("solver.iterations: {int: [0, 3]}", r"space\.solver\.iterations: with the value 0"),
    ("solver.iterations: {choice: [2]}", r"space\.solver\.iterations\.choice: expected at least two values"),
    ("solver.iterations: {int: [1, 3], when: {label: other}}", r"'other' is not one of label's labels"),
    ("solver.iterations: {int: [1, 3], when: {nope: x}}", r"'nope' is not a choice listed before it"),
    ("solver.iterations: {int: [1, 3], log: 2}", r"\.log: expected true or false"),
    ("scale: {choice: [{name: pyramid, n_scales: 5}, {name: pyramid, n_scales: 7}]}",
     r"space\.scale\.choice: two values have the label 'pyramid': give a mapping label -> value"),
])
def test_a_wrong_space_entry_names_the_file_and_key(tmp_path, data, change, message):
    path = write(tmp_path / "s.yaml", SPEC.replace("solver.iterations: {int: [1, 3]}", change))
    if message is None:
        load_search_spec(path)
        return
    with pytest.raises(ConfigError, match=message) as info:
        load_search_spec(path)
    assert str(path) in str(info.value)


@pytest.mark.parametrize("old, new, message", [
    ("base: strcf\n", "", r"base: missing"),
    ("base: strcf", "base: nowhere.yaml", r"base: config 'nowhere.yaml' not found"),
    ("folds: 2", "folds: 1", r"folds: expected a whole number >= 2, got 1"),
    ("trials: 3", "trials: 0", r"trials: expected a whole number >= 1"),
    ("folds: 2", "folds: 2\nexperiments: [reset]", r"experiments: expected one of ope, tre, sre"),
    ("folds: 2", "folds: 2\nfold: 3", r"unknown key 'fold' \(did you mean 'folds'\?\)"),
    ("baselines: {KCF: kcf}", "baselines: {KCF: nope}", r"baselines\.KCF: config 'nope' not found"),
    ("space:", "old_space:", r"unknown key 'old_space'"),
])
def test_a_wrong_spec_names_the_file_and_key(tmp_path, data, old, new, message):
    path = write(tmp_path / "s.yaml", SPEC.replace(old, new))
    with pytest.raises(ConfigError, match=message) as info:
        load_search_spec(path)
    assert str(path) in str(info.value)


def test_more_folds_than_sequences_is_refused(tmp_path, data):
    spec = load_search_spec(write(tmp_path / "s.yaml", SPEC.replace("folds: 2", "folds: 5")))
    with pytest.raises(DcfkitError, match="5 folds need at least 5 sequences, got 4"):
        Search(spec, tmp_path / "out")


def test_trial_values_depend_only_on_the_seed_and_the_recorded_trials(tmp_path, data):
    spec = load_search_spec(write(tmp_path / "s.yaml", SPEC))
    first = sample(spec, "fold1", 0, [])
    assert sample(spec, "fold1", 0, []) == first
    assert ("label.mu" in first) == (first["label"] == "repressed")  # sampled only under its choice
    recorded = [{"params": first, "value": 0.5}]
    assert sample(spec, "fold1", 1, recorded) == sample(spec, "fold1", 1, recorded)
    assert sample(spec, "fold2", 0, []) != first or sample(spec, "fold2", 1, recorded) != sample(spec, "fold1", 1, recorded)


def test_a_search_scores_each_folds_choice_on_the_sequences_it_never_saw(tmp_path, data):
    spec = load_search_spec(write(tmp_path / "s.yaml", SPEC))
    search = Search(spec, tmp_path / "out", {"jobs": 1})
    summary = search.run()
    seqs = {s.name: s for s in load_dataset("otb", data)}
    assert [f["held_out"] for f in summary["folds"]] == search.folds
    for fold in summary["folds"]:
        trials = [json.loads(p.read_text()) for p in sorted((tmp_path / "out/trials" / f"fold{fold['fold']}").glob("*.json"))]
        assert len(trials) == 3
        chosen = max(trials, key=lambda t: (t["value"], -t["number"]))
        assert fold["trial"] == chosen["number"]
        training = [n for n in seqs if n not in fold["held_out"]]
        assert set(chosen["scores"]) == set(training)  # judged on the other fold only
        # the held-out score is the chosen config's, scored independently from its stored runs
        store = ResultStore(tmp_path / "out/jobs/otb" / chosen["key"])
        held = [seqs[n] for n in fold["held_out"]]
        again = evaluate({"t": store.load(held)}, held)
        assert fold["held_out_auc"] == pytest.approx(np.mean([r["auc"] for r in again.per_sequence]))
    kcf = summary["baselines"]["KCF"]["per_sequence"]
    diff = np.mean([summary["held_out"]["per_sequence"][n]["auc"] - kcf[n]["auc"] for n in seqs])
    assert summary["comparisons"]["KCF"]["mean"] == pytest.approx(diff)
    assert (tmp_path / "out/best.yaml").is_file() and "Held-out AUC" in (tmp_path / "out/summary.md").read_text()
    load_config(tmp_path / "out/best.yaml")  # the final choice is a config dcfkit loads


def test_a_rerun_resumes_and_more_trials_extend_the_studies(tmp_path, data, capsys):
    spec = write(tmp_path / "s.yaml", SPEC.replace("trials: 3", "trials: 2"))
    out = tmp_path / "out"
    assert cli.main(["search", str(spec), "--out", str(out), "--jobs", "1"]) == 0
    first = {p.relative_to(out): p.read_bytes() for p in out.glob("trials/*/*.json")}
    assert len(first) == 3 * 2
    (out / "trials/fold2/0001.json").unlink()  # as a kill before the trial was recorded
    assert cli.main(["search", str(spec), "--out", str(out), "--jobs", "1", "--trials", "3"]) == 0
    again = {p.relative_to(out): p.read_bytes() for p in out.glob("trials/*/*.json")}
    assert len(again) == 3 * 3
    assert {k: again[k] for k in first} == first  # the same trials, the lost one redone the same
    capsys.readouterr()
    write(spec, SPEC.replace("seed: 0", "").replace("folds: 2", "folds: 2\nseed: 3"))
    assert cli.main(["search", str(spec), "--out", str(out), "--jobs", "1"]) != 0
    assert "records a different search (these differ: folds, seed)" in capsys.readouterr().err


def test_experiments_on_the_command_line_replace_the_specs_and_are_recorded(tmp_path, capsys):
    data = tmp_path / "data"
    for i, name in enumerate(("seqA", "seqB", "seqC", "seqD")):
        write_otb(data, name, seed=i, n_frames=22)  # long enough for the spec's TRE to be read
    spec = write(tmp_path / "s.yaml", SPEC.replace("trials: 3", "trials: 1\nexperiments: [tre]"))
    out = tmp_path / "out"
    assert cli.main(["search", str(spec), "--out", str(out), "--jobs", "1", "--experiments", "ope"]) == 0
    rec = json.loads((out / "trials/all/0000.json").read_text())
    seqs = load_dataset("otb", data)
    scored = evaluate({"t": ResultStore(out / "jobs/otb" / rec["key"]).load(seqs)}, seqs)
    assert rec["value"] == pytest.approx(np.mean([r["auc"] for r in scored.per_sequence]))
    assert not (out / "jobs/otb" / rec["key"] / "tre").exists()  # the spec's TRE was not run
    capsys.readouterr()
    assert cli.main(["search", str(spec), "--out", str(out), "--jobs", "1"]) != 0  # the spec's tre
    assert "these differ: experiments" in capsys.readouterr().err
    assert cli.main(["search", str(spec), "--out", str(out), "--experiments", "ope,opt"]) != 0
    assert "--experiments: expected one of ope, tre, sre, got 'opt'" in capsys.readouterr().err


@pytest.mark.slow
def test_a_search_killed_with_sigkill_resumes_to_the_same_result(tmp_path, data):
    spec = write(tmp_path / "s.yaml", SPEC)
    cmd = [sys.executable, "-m", "dcfkit.cli", "search", str(spec), "--jobs", "2"]
    subprocess.run([*cmd, "--out", str(tmp_path / "whole")], check=True, capture_output=True, timeout=300)
    out = tmp_path / "killed"
    proc = subprocess.Popen([*cmd, "--out", str(out)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 120
        while len(done_sidecars(out)) < 3 and proc.poll() is None and time.monotonic() < deadline:
            time.sleep(0.01)
        proc.send_signal(signal.SIGKILL)  # mid-trial: some of its runs stored, its record not written
    finally:
        proc.kill()
        proc.wait()
    assert proc.returncode == -signal.SIGKILL and not (out / "summary.json").exists()
    subprocess.run([*cmd, "--out", str(out)], check=True, capture_output=True, timeout=300)
    for path in (tmp_path / "whole").glob("trials/*/*.json"):
        assert (out / path.relative_to(tmp_path / "whole")).read_bytes() == path.read_bytes(), path
    whole, again = (json.loads((d / "summary.json").read_text()) for d in (tmp_path / "whole", out))
    assert again == {**whole, "spec": again["spec"]}
