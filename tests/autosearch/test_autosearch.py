"""dcfkit search: spec validation, folds, reproducible sampling, held-out scoring, resume.

Datasets are tiny synthetic sequences in the OTB layout (as the ablation tests write them)."""
from __future__ import annotations

import dataclasses
import json
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from test_ablation import write_otb

from dcfkit import cli
from dcfkit.ablation import load_spec
from dcfkit.analysis.scoring import evaluate
from dcfkit.autosearch import Search, SearchSpec, load_search_spec, make_folds
from dcfkit.autosearch.warm_start import base_params
from dcfkit.autosearch.study import sample
from dcfkit.autosearch.summary import best
from dcfkit.config import load_config
from dcfkit.datasets import DatasetWarning, load_dataset
from dcfkit.errors import ConfigError, DcfkitError
from dcfkit.store.results import ResultStore

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


STUDIES = ("fold1", "fold2", "all")  # SPEC's: two folds, then the final study


def records(out: Path) -> list[Path]:
    """The trial records, OUT/trials/<study>/<n>.json."""
    return sorted(p for study in STUDIES for p in (out / "trials" / study).glob("*.json"))


def trial_runs(out: Path) -> list[Path]:
    """The sidecars of the trials' finished runs, OUT/runs/<run key>/<sequence>.json."""
    return list(out.glob("runs/*/*.json"))


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
    ("solver.iterations: {float: [1, 3]}", r"space\.solver\.iterations: with the value 1\.764: .*expected an integer"),
    ("solver.iterations: {choice: {1: 2, '1': 3}}", r"space\.solver\.iterations\.choice: two labels read as '1'"),
    ("solver.iterations: {choice: {true: 2, 'True': 3}}",
     r"space\.solver\.iterations\.choice: two labels read as 'True'"),
])
def test_a_wrong_space_entry_names_the_file_and_key(tmp_path, data, change, message):
    path = write(tmp_path / "s.yaml", SPEC.replace("solver.iterations: {int: [1, 3]}", change))
    if message is None:
        load_search_spec(path)
        return
    with pytest.raises(ConfigError, match=message) as info:
        load_search_spec(path)
    assert str(path) in str(info.value)


def test_a_dimension_of_one_choice_only_needs_when_before_the_first_trial(tmp_path, data):
    """The base's label takes mu, so each dimension alone resolves; the space also makes
    label=gaussian with label.mu, which used to fail in the trial that sampled it."""
    text = SPEC.replace("base: strcf", "base: dr2track").replace(", when: {label: repressed}", "")
    with pytest.raises(ConfigError, match=r": space: label='gaussian', label\.mu=0\.05 together give no valid config "
                                          r"\(a dimension that only some choices take needs when\)") as info:
        load_search_spec(write(tmp_path / "s.yaml", text))
    assert str(tmp_path / "s.yaml") in str(info.value)
    load_search_spec(write(tmp_path / "s.yaml", SPEC.replace("base: strcf", "base: dr2track")))  # with its when


def test_a_repeated_sequence_counts_once_in_specs_and_on_the_command_line(tmp_path, data):
    listed = "sequences: [" + ", ".join(["seqA"] * 10) + ", seqB, seqC, seqD]\n"
    path = write(tmp_path / "s.yaml", SPEC.replace("folds: 2", "folds: 3") + listed)
    with pytest.warns(DatasetWarning, match=r"s\.yaml: sequences: 'seqA' listed more than once: each sequence counts "
                                            r"once \(4 in all\)"):
        spec = load_search_spec(path)
    search = Search(spec, tmp_path / "out")
    assert search.names == ["seqA", "seqB", "seqC", "seqD"]
    assert sorted(n for fold in search.folds for n in fold) == search.names  # held out once each
    with pytest.warns(DatasetWarning, match=r"'seqA' listed more than once"):  # the ablation's spec: the same rule
        assert load_spec(write(tmp_path / "a.yaml", listed + "dataset: {name: otb, root: data}\nvariants: {k: kcf}\n")
                         ).sequences == ("seqA", "seqB", "seqC", "seqD")
    with pytest.warns(DatasetWarning, match=r"sequences for OTB at .*: 'seqB' listed more than once"):  # --sequences
        assert [s.name for s in load_dataset("otb", data, "seqB,seqA,seqb")] == ["seqB", "seqA"]


def test_a_sequence_without_a_scored_frame_leaves_the_objective_and_the_json_valid(tmp_path):
    """Under got10k a one-frame sequence has no scored frame (frame 1 never counts): its AUC is
    NaN for every config. It is left out of the means; a trial with no score at all (as recorded,
    with a bare NaN, by dcfkit 0.9.0) is a failed trial, and a resume goes on."""
    data = tmp_path / "data"
    for i, name in enumerate(("seqA", "seqB", "seqC", "seqD")):
        write_otb(data, name, seed=i, n_frames=1 if name == "seqD" else 8)
    spec = write(tmp_path / "s.yaml", SPEC.replace("trials: 3", "trials: 1"))
    out = tmp_path / "out"
    strict = {"parse_constant": lambda name: pytest.fail(f"bare {name} in JSON")}
    assert cli.main(["search", str(spec), "--out", str(out), "--jobs", "1", "--protocol", "got10k"]) == 0
    summary = json.loads((out / "summary.json").read_text(), **strict)
    assert summary["unscored"] == ["seqD"] and summary["held_out"]["per_sequence"]["seqD"]["auc"] is None
    assert summary["held_out"]["auc"]["n"] == 3 and summary["comparisons"]["KCF"]["n"] == 3
    record = json.loads((out / "trials/all/0000.json").read_text(), **strict)
    assert record["value"] == pytest.approx(np.mean([record["scores"][n]["auc"] for n in ("seqA", "seqB", "seqC")]))
    # a record without a score, as 0.9.0 wrote it, then a resume with one more trial
    (out / "trials/all/0000.json").write_text(json.dumps({**record, "value": float("nan")}))
    assert cli.main(["search", str(spec), "--out", str(out), "--jobs", "1", "--protocol", "got10k",
                     "--trials", "2"]) == 0
    summary = json.loads((out / "summary.json").read_text(), **strict)
    assert summary["final"]["trial"] == 1  # a trial without a score is never the best
    with pytest.raises(DcfkitError, match=r"study fold2: none of its 2 trials has a score"):
        best([{"number": 0, "value": None}, {"number": 1, "value": float("nan")}], "fold2")


def test_a_resume_on_other_data_of_the_same_names_is_refused(tmp_path, data, capsys):
    spec = write(tmp_path / "s.yaml", SPEC.replace("trials: 3", "trials: 1"))
    out = tmp_path / "out"
    assert cli.main(["search", str(spec), "--out", str(out), "--jobs", "1"]) == 0
    other = tmp_path / "other"
    shutil.copytree(data, other)
    gt = other / "seqC/groundtruth_rect.txt"  # the same name, length and first box; a later box moved
    lines = gt.read_text().splitlines()
    gt.write_text("\n".join([*lines[:-1], "5,5,16,20"]) + "\n")
    capsys.readouterr()
    assert cli.main(["search", str(spec), "--out", str(out), "--jobs", "1", "--root", str(other)]) != 0
    err = capsys.readouterr().err
    assert "search.json: its trials were made on other data: the frames or ground truth of 'seqC' under " in err
    assert "give the recorded search's --root, or a new --out" in err
    assert cli.main(["search", str(spec), "--out", str(out), "--jobs", "1", "--root", str(shutil.copytree(
        data, tmp_path / "copy"))]) == 0  # a copy of the same data is the same data
    record = json.loads((out / "search.json").read_text())  # as dcfkit 0.9.0 wrote it: no identity, trusted
    del record["fingerprint"]["data"]
    (out / "search.json").write_text(json.dumps(record))
    assert cli.main(["search", str(spec), "--out", str(out), "--jobs", "1"]) == 0
    assert "data" in json.loads((out / "search.json").read_text())["fingerprint"]


def test_a_sequence_whose_ground_truth_is_withheld_is_left_out_of_the_search(tmp_path, data, monkeypatch, caplog):
    spec = load_search_spec(write(tmp_path / "s.yaml", SPEC.replace("trials: 3", "trials: 1")))
    loaded = spec.load_sequences()  # seqC as a test split's: frame 1's box only (it used to be a KeyError)
    monkeypatch.setattr(SearchSpec, "load_sequences", lambda self: [
        dataclasses.replace(s, ground_truth_withheld=s.name == "seqC") for s in loaded])
    with caplog.at_level("WARNING"):
        summary = Search(spec, tmp_path / "out", {"jobs": 1}).run()
    assert summary["sequences"] == ["seqA", "seqB", "seqD"] and "withheld after frame 1" in caplog.text


@pytest.mark.parametrize("old, new, message", [
    ("base: strcf\n", "", r"base: missing"),
    ("base: strcf", "base: nowhere.yaml", r"base: config 'nowhere.yaml' not found"),
    ("folds: 2", "folds: 1", r"folds: expected a whole number >= 2, got 1"),
    ("trials: 3", "trials: 0", r"trials: expected a whole number >= 1"),
    ("trials: 3", "trials: 3\nwarm_start: 'no'", r"warm_start: expected true or false, got 'no'"),
    ("trials: 3", "trials: 3\nfinal_study: sometimes", r"final_study: expected one of always, if_it_wins, got 'some"),
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
        store = ResultStore(tmp_path / "out/runs" / chosen["key"])
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
    first = {p.relative_to(out): p.read_bytes() for p in records(out)}
    assert len(first) == 3 * 2
    (out / "trials/fold2/0001.json").unlink()  # as a kill before the trial was recorded
    damaged = json.loads((out / "trials/fold1/0001.json").read_text())  # an edited record is run again
    (out / "trials/fold1/0001.json").write_text(json.dumps({**damaged, "params": {"solver.iterations": 99}}))
    assert cli.main(["search", str(spec), "--out", str(out), "--jobs", "1", "--trials", "3"]) == 0
    again = {p.relative_to(out): p.read_bytes() for p in records(out)}
    assert len(again) == 3 * 3
    assert {k: again[k] for k in first} == first  # the same trials, the lost one redone the same
    capsys.readouterr()
    write(spec, SPEC.replace("seed: 0", "").replace("folds: 2", "folds: 2\nseed: 3"))
    assert cli.main(["search", str(spec), "--out", str(out), "--jobs", "1"]) != 0
    assert "records a different search (these differ: folds, seed)" in capsys.readouterr().err


def test_a_resume_with_other_box_code_is_refused_saying_why(tmp_path, data, capsys, monkeypatch):
    from dcfkit.autosearch import evaluation

    spec = write(tmp_path / "s.yaml", SPEC.replace("trials: 3", "trials: 1"))
    (tmp_path / "out").mkdir()
    Search(load_search_spec(spec), tmp_path / "out", {"jobs": 1}).check_record()
    monkeypatch.setattr(evaluation, "dcfkit_version", lambda: "0.0.1")  # as another version or box code
    assert cli.main(["search", str(spec), "--out", str(tmp_path / "out"), "--status"]) != 0
    err = capsys.readouterr().err
    assert "these differ: base, space; the base config's run key differs: another base config, dcfkit version " \
           "or box code (a search resumes with the code that recorded it)" in err


def test_experiments_on_the_command_line_replace_the_specs_and_are_recorded(tmp_path, capsys):
    data = tmp_path / "data"
    for i, name in enumerate(("seqA", "seqB", "seqC", "seqD")):
        write_otb(data, name, seed=i, n_frames=22)  # long enough for the spec's TRE to be read
    spec = write(tmp_path / "s.yaml", SPEC.replace("trials: 3", "trials: 1\nexperiments: [tre]"))
    out = tmp_path / "out"
    assert cli.main(["search", str(spec), "--out", str(out), "--jobs", "1", "--experiments", "ope"]) == 0
    rec = json.loads((out / "trials/all/0000.json").read_text())
    seqs = load_dataset("otb", data)
    scored = evaluate({"t": ResultStore(out / "runs" / rec["key"]).load(seqs)}, seqs)
    assert rec["value"] == pytest.approx(np.mean([r["auc"] for r in scored.per_sequence]))
    assert not (out / "runs" / rec["key"] / "tre").exists()  # the spec's TRE was not run
    capsys.readouterr()
    assert cli.main(["search", str(spec), "--out", str(out), "--jobs", "1"]) != 0  # the spec's tre
    assert "these differ: experiments" in capsys.readouterr().err
    assert cli.main(["search", str(spec), "--out", str(out), "--experiments", "ope,opt"]) != 0
    assert "--experiments: expected one of ope, tre, sre, got 'opt'" in capsys.readouterr().err


@pytest.mark.slow
def test_a_search_killed_with_sigkill_resumes_to_the_same_result(tmp_path, data):
    spec = write(tmp_path / "s.yaml", SPEC.replace("trials: 3", "trials: 2"))  # the base, then one sampled
    cmd = [sys.executable, "-m", "dcfkit.cli", "search", str(spec), "--jobs", "2"]
    subprocess.run([*cmd, "--out", str(tmp_path / "whole")], check=True, capture_output=True, timeout=300)
    out = tmp_path / "killed"
    proc = subprocess.Popen([*cmd, "--out", str(out)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 120
        while len(trial_runs(out)) < 3 and proc.poll() is None and time.monotonic() < deadline:
            time.sleep(0.01)
        proc.send_signal(signal.SIGKILL)  # mid-trial: some of its runs stored, its record not written
    finally:
        proc.kill()
        proc.wait()
    assert proc.returncode == -signal.SIGKILL and not (out / "summary.json").exists()
    subprocess.run([*cmd, "--out", str(out)], check=True, capture_output=True, timeout=300)
    for path in records(tmp_path / "whole"):
        assert (out / path.relative_to(tmp_path / "whole")).read_bytes() == path.read_bytes(), path
    whole, again = (json.loads((d / "summary.json").read_text()) for d in (tmp_path / "whole", out))
    assert again == {**whole, "spec": again["spec"]}


def test_trials_of_one_config_share_their_runs_and_a_baseline_has_its_own_folder(tmp_path, data, monkeypatch,
                                                                                   capsys):
    """A baseline of a trial's config (the base, trial 0) gets the trial's runs copied into its
    own folder, tracking nothing; a baseline of another config tracks its own."""
    from test_evaluation import DriftTracker  # a fake tracker: the runs it makes are counted

    from dcfkit.autosearch.evaluation import Evaluator
    from dcfkit.running import runner

    made = []
    monkeypatch.setattr(runner, "_warm_up", lambda task: None)
    monkeypatch.setattr(runner, "load_dcfkit_tracker", lambda config: made.append(config) or DriftTracker(config))
    out, names = tmp_path / "out", ["seqA", "seqB"]
    evaluator = Evaluator(out, "otb", load_dataset("otb", data), ["ope"], jobs=1, baselines=["KCF"])
    config = load_config("kcf")
    first = evaluator.scores(config, names)
    assert len(made) == 2 and sorted(p.name for p in (out / "runs" / evaluator.key(config)).glob("*.txt")) == [
        "seqA.txt", "seqB.txt"]  # OUT/runs/<run key>/
    assert evaluator.scores({**config, "name": "trial 7"}, names) == first and len(made) == 2  # its runs reused
    assert evaluator.scores(config, names, baseline="KCF") == first and len(made) == 2  # copied, not tracked
    assert sorted(p.name for p in (out / "baselines" / "KCF").glob("*.txt")) == ["seqA.txt", "seqB.txt"]
    trial = out / "runs" / evaluator.key(config)
    assert all((out / "baselines" / "KCF" / p.name).read_bytes() == p.read_bytes() for p in trial.glob("seq*"))
    other = {**config, "solver": {**config["solver"], "sigma": 0.7}}
    evaluator.scores(other, names, baseline="KCF")  # the folder's runs are of another key: tracked again
    assert len(made) == 4
    assert cli.main(["compare", str(out / "runs" / evaluator.key(config)), str(out / "baselines" / "KCF"),
                     "--dataset", "otb", "--root", str(data)]) == 0  # eval's layout: compare reads it


def test_a_search_warns_once_of_runs_in_the_old_layout(tmp_path, data, caplog):
    spec = load_search_spec(write(tmp_path / "s.yaml", SPEC.replace("trials: 3", "trials: 1")))
    (tmp_path / "out" / "jobs" / "otb").mkdir(parents=True)  # as dcfkit 0.10 kept a search's runs
    with caplog.at_level("WARNING"):
        Search(spec, tmp_path / "out", {"jobs": 1}).run()
    said = [r.getMessage() for r in caplog.records if "old layout" in r.getMessage()]
    assert len(said) == 1 and "OUT/runs/<run key>/, OUT/baselines/<name>/" in said[0]
    assert (tmp_path / "out" / "baselines" / "KCF").is_dir()


def test_trial_0_of_every_study_is_the_base_so_no_study_ends_below_it(tmp_path, data):
    spec = load_search_spec(write(tmp_path / "s.yaml", SPEC.replace("trials: 3", "trials: 2")))
    assert spec.warm_start
    Search(spec, tmp_path / "out", {"jobs": 1}).run()
    base = json.loads(json.dumps(spec.base))
    for study in STUDIES:
        trials = [json.loads(p.read_text()) for p in sorted((tmp_path / "out/trials" / study).glob("*.json"))]
        # strcf as a point of the space: its label's choice, its θ and ADMM iterations
        assert trials[0]["params"] == {"label": "gaussian", "regularizers.temporal.theta": 15.0, "solver.iterations": 2}
        assert trials[0]["config"] == base
        assert max(t["value"] for t in trials) >= trials[0]["value"]


def test_a_base_outside_the_space_is_trial_0_by_its_score_alone(tmp_path, data):
    outside = SPEC.replace("float: [4, 40]", "float: [20, 40]")  # strcf's θ is 15
    spec = load_search_spec(write(tmp_path / "s.yaml", outside))
    params = base_params(spec)
    assert params == {} and spec.config(params) == spec.base
    assert sample(spec, "fold1", 1, [{"params": params, "value": 0.4}])  # TPE takes a trial without values


def test_warm_start_false_samples_trial_0_and_a_resume_across_the_switch_is_refused(tmp_path, data, capsys):
    spec = write(tmp_path / "s.yaml", SPEC.replace("trials: 3", "trials: 1\nwarm_start: false"))
    out = tmp_path / "out"
    assert cli.main(["search", str(spec), "--out", str(out), "--jobs", "1"]) == 0
    rec = json.loads((out / "trials/fold1/0000.json").read_text())
    assert rec["params"] == sample(load_search_spec(spec), "fold1", 0, [])
    write(spec, SPEC.replace("trials: 3", "trials: 1"))
    capsys.readouterr()
    assert cli.main(["search", str(spec), "--out", str(out), "--jobs", "1"]) != 0
    assert "made with warm_start: false (trial 0 sampled), this spec has warm_start: true" in capsys.readouterr().err
    write(spec, SPEC.replace("trials: 3", "trials: 1\nwarm_start: 1"))
    with pytest.raises(ConfigError, match="warm_start: expected true or false, got 1"):
        load_search_spec(spec)


def test_a_choice_keeps_its_values_after_the_spec_check(tmp_path, data):
    """Checking the space resolved each choice with its dimensions at both ends of their ranges,
    and the resolving wrote those ends into the choice's own mapping: a trial that did not
    sample label.mu (top_n 30) then ran with mu 1.0, the range's end, not the spec's 0.25."""
    nested = SPEC.replace("  label: {choice: {gaussian: {name: gaussian}, repressed: {name: distractor_repressed}}}\n"
                          "  label.mu: {float: [0.05, 1.0], log: true, when: {label: repressed}}\n",
                          "  label: {choice: {gaussian: {name: gaussian}, repressed: {name: distractor_repressed, mu: 0.25}}}\n"
                          "  label.top_n: {choice: [10, 30], when: {label: repressed}}\n"
                          "  label.mu: {float: [0.05, 1.0], when: {label.top_n: '10'}}\n")
    spec = load_search_spec(write(tmp_path / "s.yaml", nested))
    assert spec.parameters[0].choices["repressed"] == {"name": "distractor_repressed", "mu": 0.25}
    config = spec.config({"label": "repressed", "label.top_n": "30", "regularizers.temporal.theta": 10.0,
                          "solver.iterations": 2})
    assert (config["label"]["mu"], config["label"]["top_n"]) == (0.25, 30)


@pytest.mark.parametrize("name", ["uav", "lineage"])
def test_the_shipped_base_is_a_point_of_the_shipped_space(tmp_path, name):
    """Trial 0 of the shipped searches is DR²Track placed in the space, so TPE models the trials
    around it (no data is read to place it)."""
    spec = load_search_spec(name, root=[tmp_path] * 4)
    params = base_params(spec)
    assert params["label"] == "repressed" and params["scale"] == "dsst" and params["label.mu"] == 0.25
    assert spec.config(params) == spec.base
    if name == "lineage":  # the broadened dimensions, each absent in the base
        assert (params["mask"], params["channel_weights"], params["reliability"]) == ("none",) * 3
        assert "schedule" not in params and "redetect" not in params  # sampled only under lmcf


def test_a_search_record_without_its_fingerprint_is_refused_in_one_line(tmp_path, data, capsys):
    spec = write(tmp_path / "s.yaml", SPEC.replace("trials: 3", "trials: 1"))
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "search.json").write_text('{"name": "tiny"}', encoding="utf-8")
    assert cli.main(["search", str(spec), "--out", str(tmp_path / "out"), "--status"]) != 0
    assert "search.json holds no search fingerprint: not a search record as dcfkit writes it" in \
        capsys.readouterr().err
