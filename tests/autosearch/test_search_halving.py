"""dcfkit search with successive halving (issue 42): Optuna's pruner with the sequence count as
the budget, checked against a brute-force successive halving, replayed from the records on a
resume, and against the plain search on the same seed."""
from __future__ import annotations

import json
import random
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from test_ablation import write_otb

from dcfkit import cli
from dcfkit.autosearch import Search, load_search_spec
from dcfkit.autosearch.halving import Halving, Ladder, sequence_order
from dcfkit.errors import ConfigError

pytest.importorskip("optuna")

SPEC = """
name: halved
dataset: {name: otb, root: data}
base: kcf
folds: 2
trials: 6
startup_trials: 3
baselines: {KCF: kcf}
space:
  solver.sigma: {float: [0.1, 2.0], log: true}
  tracker.output_sigma_factor: {float: [0.02, 0.3]}
"""
HALVING = "halving: {min_sequences: 1, reduction_factor: 2}\n"
STUDIES = ("fold1", "fold2", "all")


@pytest.fixture(scope="module")
def searches(tmp_path_factory) -> Path:
    """A folder with ``data`` (six synthetic sequences) and two searches of one seed run to their
    end: ``plain`` and ``halved`` (``plain.yaml`` with :data:`HALVING`)."""
    folder = tmp_path_factory.mktemp("halving")
    for i in range(6):
        write_otb(folder / "data", f"seq{i}", seed=i, n_frames=8)
    for name, text in (("plain", SPEC), ("halved", SPEC + HALVING)):
        (folder / f"{name}.yaml").write_text(text, encoding="utf-8")
        Search(load_search_spec(folder / f"{name}.yaml"), folder / name, {"jobs": 1}).run()
    return folder


def trials(out: Path, study: str) -> list[dict]:
    return [json.loads(p.read_text()) for p in sorted((out / "trials" / study).glob("*.json"))]


def brute_force(values: list[list[float]], rungs: list[int], eta: int) -> list[int]:
    """Asynchronous successive halving by hand: trial by trial, rung by rung, a trial goes on
    past rung k only if its value is at least the ⌊m/η⌋-th largest (the largest if ⌊m/η⌋ is
    0) of the m values at rung k of the trials before it and its own. Returns how many rungs
    each trial reached."""
    at_rung: list[list[float]] = [[] for _ in rungs]
    reached = []
    for trial in values:
        k = 0
        while True:
            at_rung[k].append(trial[k])
            if k == len(rungs) - 1:
                break
            ranked = sorted(at_rung[k], reverse=True)
            if trial[k] < ranked[max(len(ranked) // eta, 1) - 1]:
                break
            k += 1
        reached.append(k + 1)
    return reached


@pytest.mark.parametrize("eta, first, n", [(2, 1, 6), (3, 2, 20), (2, 3, 21)])
def test_the_ladder_prunes_as_successive_halving_by_hand(eta, first, n):
    halving = Halving(first, eta)
    rungs = halving.rungs(n)
    assert rungs[0] == first and rungs[-1] == n and all(b == a * eta for a, b in zip(rungs, rungs[1:-1]))
    rng = random.Random(eta * 100 + n)
    values = [[round(rng.random(), 2) for _ in rungs] for _ in range(40)]  # ties among them
    ladder, reached = Ladder(halving, n), []
    for trial in values:
        steps, pruned = ladder.climb(lambda start, stop, v=trial: v[rungs.index(stop)])
        assert [s[0] for s in steps] == rungs[:len(steps)] and pruned == (len(steps) < len(rungs))
        reached.append(len(steps))
    assert reached == brute_force(values, rungs, eta)
    assert 0 < reached.count(len(rungs)) < len(values)  # some pruned, some not


def test_a_rung_without_a_score_judges_nothing_and_replays_alike():
    """A rung of sequences without a scored frame (whatever the config: a one-frame sequence
    under got10k) has no mean: the trial goes on, and the next rung judges it."""
    ladder, made = Ladder(Halving(1, 2), 4), []
    for late in (0.6, 0.5, 0.7):
        made.append(ladder.climb(lambda start, stop, v=late: None if stop == 1 else v))
    assert made == [([[1, None], [2, 0.6], [4, 0.6]], False),  # the base: never pruned
                    ([[1, None], [2, 0.5]], True),  # at 2 sequences, below 0.6
                    ([[1, None], [2, 0.7], [4, 0.7]], False)]
    again = Ladder(Halving(1, 2), 4)
    assert [again.replay(steps, pruned) for steps, pruned in made] == [None] * 3


def test_a_replay_names_the_first_rung_where_a_record_parts_from_the_rule():
    ladder = Ladder(Halving(1, 2), 4)
    for value in (0.9, 0.8):
        ladder.climb(lambda start, stop, v=value: v)
    # at 1 sequence, 0.1 is not in the top half of (0.9, 0.8, 0.1): the rule prunes it there
    assert ladder.replay([[1, 0.1], [2, 0.5], [4, 0.5]], False) == \
        "pruned: false after 1 sequence, where successive halving prunes it"
    assert Ladder(Halving(1, 2), 4).replay([[1, 0.1], [2, 0.5]], False) == \
        "steps: a trial not pruned reaches every rung, [1, 2, 4]"


def test_the_spec_key_is_checked_where_it_is_read(tmp_path):
    for bad, message in (("halving: 3", "halving: expected a mapping"),
                         ("halving: {min_sequences: 0, reduction_factor: 2}", "halving.min_sequences: expected a "
                                                                             "whole number >= 1, got 0"),
                         ("halving: {min_sequences: 2, reduction_factor: 1}", "halving.reduction_factor: expected "
                                                                             "a whole number >= 2, got 1"),
                         ("halving: {min_sequences: 2}", "halving.reduction_factor: missing (a whole number >= 2)"),
                         ("halving: {min_sequences: 2, reduction_factor: 2, rungs: 3}", "'rungs': not a key")):
        (tmp_path / "s.yaml").write_text(SPEC + bad + "\n", encoding="utf-8")
        with pytest.raises(ConfigError, match=re.escape(message)) as err:
            load_search_spec(tmp_path / "s.yaml")
        assert str(tmp_path / "s.yaml") in str(err.value)


def test_pruned_trials_score_a_prefix_of_the_studys_order_and_never_win(searches):
    spec = load_search_spec(searches / "halved.yaml")
    search = Search(spec, searches / "halved", {"jobs": 1})
    pruned = 0
    for study in STUDIES:
        names, order = search.training(study), sequence_order(search.training(study), spec.seed, study)
        assert sorted(order) == sorted(names)
        for rec in trials(searches / "halved", study):
            counts = [s[0] for s in rec["steps"]]
            assert counts == spec.halving.rungs(len(names))[:len(counts)]
            assert list(rec["scores"]) == order[:counts[-1]]
            if rec["pruned"]:
                pruned += 1
                assert rec["value"] is None and counts[-1] < len(names)
            else:
                assert sorted(rec["scores"]) == sorted(names) and rec["value"] is not None
    assert pruned > 0
    summary = json.loads((searches / "halved/summary.json").read_text())
    assert summary["final"]["trial"] in [r["number"] for r in trials(searches / "halved", "all") if not r["pruned"]]
    assert sum(s["pruned"] for s in summary["halving"]["studies"].values()) == pruned
    saved = summary["halving"]["studies"]["all"]
    assert saved["frames"] < saved["frames_unpruned"] == 6 * 6 * 8  # six trials, six sequences of 8 frames
    assert f"{pruned} of 18 trials pruned" in (searches / "halved/summary.md").read_text()


def test_a_trial_left_unpruned_scores_as_in_the_plain_search(searches):
    """Trial 0 (the base) and the startup trials are sampled alike in both searches: the ones
    halving lets through have the plain search's scores, bit for bit."""
    for study in STUDIES:
        plain, halved = trials(searches / "plain", study), trials(searches / "halved", study)
        for a, b in zip(plain[:3], halved[:3]):  # startup_trials: 3
            assert a["params"] == b["params"] and a["key"] == b["key"]
            if not b["pruned"]:
                assert a["value"] == b["value"] and a["scores"] == b["scores"]
        assert not halved[0]["pruned"]  # the base is the first at every rung


def test_a_resume_replays_the_pruner_and_runs_nothing(searches, tmp_path, capsys):
    out = tmp_path / "halved"
    shutil.copytree(searches / "halved", out)
    before = {p: p.read_bytes() for p in out.glob("trials/*/*.json")}
    runs = sorted(out.glob("runs/*/*.json"))
    spec = tmp_path / "halved.yaml"
    spec.write_text(SPEC.replace("root: data", f"root: {searches / 'data'}") + HALVING, encoding="utf-8")
    assert cli.main(["search", str(spec), "--out", str(out), "--jobs", "1"]) == 0
    assert {p: p.read_bytes() for p in out.glob("trials/*/*.json")} == before
    assert sorted(out.glob("runs/*/*.json")) == runs
    spec.write_text(spec.read_text().replace(HALVING, ""), encoding="utf-8")
    capsys.readouterr()
    assert cli.main(["search", str(spec), "--out", str(out), "--jobs", "1"]) != 0
    assert ("made with halving: {min_sequences: 1, reduction_factor: 2, experiments: together}, this spec has "
            "halving: none"
            in capsys.readouterr().err)


def test_a_record_whose_pruning_was_edited_is_redone(searches, tmp_path, caplog):
    out = tmp_path / "halved"
    shutil.copytree(searches / "halved", out)
    spec = tmp_path / "halved.yaml"
    spec.write_text(SPEC.replace("root: data", f"root: {searches / 'data'}") + HALVING, encoding="utf-8")
    search = Search(load_search_spec(spec), out, {"jobs": 1})
    study = "all"
    rec = next(r for r in trials(out, study) if not r["pruned"])  # the base, at least
    first = rec["steps"][0][0]
    order = search.order(study)
    path = out / "trials" / study / f"{rec['number']:04d}.json"
    # a record consistent in itself: pruned at the first rung, scored on its sequences only
    edited = {**rec, "pruned": True, "value": None, "steps": rec["steps"][:1],
              "scores": {n: rec["scores"][n] for n in order[:first]}}
    path.write_text(json.dumps(edited), encoding="utf-8")
    records, _ = search.recorded(study)
    assert len(records) == rec["number"]
    assert "successive halving continues it" in caplog.text and str(path) in caplog.text
    done = search.run_study(study)
    assert done[rec["number"]] == rec  # redone to the same record


def test_the_halving_benchmark_replays_the_plain_trials_and_compares_the_halved(searches):
    script = Path(__file__).resolve().parents[2] / "benchmarks" / "halving.py"
    done = subprocess.run([sys.executable, str(script), str(searches / "plain.yaml"), str(searches / "plain"),
                           "--settings", "1x2,9x2", "--halved", str(searches / "halved")],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    replay_9x2, ran = done.stdout.split("\nReplayed: ")[2].split("\nRun: ")
    # a first rung beyond every study's sequences prunes nothing
    assert "all studies: 0 of 18 trials pruned, 100% of the frames" in replay_9x2
    summary = json.loads((searches / "halved/summary.json").read_text())
    pruned = sum(s["pruned"] for s in summary["halving"]["studies"].values())
    assert f"all studies: {pruned} of 18 trials pruned" in ran
