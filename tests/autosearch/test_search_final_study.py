"""The final study comes after the held-out verdict: with ``final_study: if_it_wins`` it runs
only if the folds' choices beat every baseline held out (docs/search.md, "What it does")."""
from __future__ import annotations

import json

import pytest
from test_ablation import write_otb

from dcfkit import cli
from dcfkit.autosearch import Search, load_search_spec, study

pytest.importorskip("optuna")

SPEC = """
name: final
dataset: {name: otb, root: data}
base: kcf
folds: 2
trials: 2
startup_trials: 1
baselines: {KCF: kcf}
space:
  solver.sigma: {float: [0.1, 2.0], log: true}
"""
VERDICT = ("folds", "held_out", "baselines", "comparisons", "beats_every_baseline", "unscored")


@pytest.fixture
def data(tmp_path):
    for i, name in enumerate(("seqA", "seqB", "seqC", "seqD")):
        write_otb(tmp_path / "data", name, seed=i, n_frames=8)
    return tmp_path / "data"


def spec_file(tmp_path, extra: str = "", name: str = "s.yaml"):
    path = tmp_path / name
    path.write_text(SPEC + extra, encoding="utf-8")
    return path


def status(spec, out, capsys, *options) -> list[str]:
    capsys.readouterr()
    assert cli.main(["search", str(spec), "--out", str(out), "--status", *options]) == 0
    return capsys.readouterr().out.splitlines()


def trials(out, name):
    return sorted((out / "trials" / name).glob("*.json"))


def test_if_it_wins_skips_the_final_study_when_the_folds_lose(tmp_path, data, capsys):
    """Four sequences cannot beat a baseline (Wilcoxon's smallest two-sided p over four pairs is
    0.125), so the folds lose: the verdict is the full search's, the final study never runs, and
    a best.yaml left by an earlier run is removed, not read as this search's choice."""
    spec = spec_file(tmp_path)
    assert cli.main(["search", str(spec), "--out", str(tmp_path / "always"), "--jobs", "1"]) == 0
    out = tmp_path / "skipping"
    out.mkdir()
    (out / "best.yaml").write_text("name: stale\n")
    capsys.readouterr()
    skipping = spec_file(tmp_path, "final_study: if_it_wins\n", "skipping.yaml")
    assert cli.main(["search", str(skipping), "--out", str(out), "--jobs", "1"]) == 0
    printed = capsys.readouterr()
    whole, skipped = (json.loads((d / "summary.json").read_text()) for d in (tmp_path / "always", out))
    assert {k: skipped[k] for k in VERDICT} == {k: whole[k] for k in VERDICT}
    assert not whole["beats_every_baseline"] and whole["final"]["trial"] in (0, 1) and len(trials(tmp_path / "always",
                                                                                                  "all")) == 2
    assert skipped["final"] is None and skipped["final_study"] == "if_it_wins" and trials(out, "all") == []
    assert not (out / "best.yaml").exists()
    assert "Final study: not run (`final_study: if_it_wins`, and the folds lost); no best.yaml." in printed.out
    assert "0 of 1 baselines beaten: the final study is skipped (final_study: if_it_wins)" in printed.err
    assert status(skipping, out, capsys)[-2:] == [
        "  all: not begun; skipped: the folds lost held out (final_study: if_it_wins)", "summary.md: written"]
    assert status(spec, out, capsys)[-2:] == [  # under always, a rerun would run it
        "  all: not begun", "summary.md: not yet: it is written when the studies it runs are complete"]
    assert status(skipping, out, capsys, "--trials", "3")[-1].startswith("summary.md: not yet")  # another budget


def test_a_final_study_recorded_before_is_read_when_complete_and_not_continued_when_not(tmp_path, data, capsys):
    """A search recorded with ``always`` resumed under ``if_it_wins``: its complete final study
    costs nothing and is reported (best.yaml kept); one stopped part-way is left as it is, and
    the summary says after how many trials."""
    out = tmp_path / "out"
    assert cli.main(["search", str(spec_file(tmp_path)), "--out", str(out), "--jobs", "1"]) == 0
    whole = json.loads((out / "summary.json").read_text())
    skipping = spec_file(tmp_path, "final_study: if_it_wins\n", "skipping.yaml")
    assert cli.main(["search", str(skipping), "--out", str(out), "--jobs", "1"]) == 0
    assert json.loads((out / "summary.json").read_text())["final"] == whole["final"] and (out / "best.yaml").is_file()
    trials(out, "all")[-1].unlink()
    capsys.readouterr()
    assert cli.main(["search", str(skipping), "--out", str(out), "--jobs", "1"]) == 0
    assert "(`final_study: if_it_wins`, and the folds lost, after 1 of 2 trials of an earlier run)" in \
        capsys.readouterr().out
    assert len(trials(out, "all")) == 1 and not (out / "best.yaml").exists()
    assert status(skipping, out, capsys)[-2].endswith("; skipped: the folds lost held out (final_study: if_it_wins)")


def test_a_skipped_final_study_under_halving_counts_the_fold_studies_alone(tmp_path, data):
    spec = load_search_spec(spec_file(tmp_path, "final_study: if_it_wins\n"
                                                "halving: {min_sequences: 1, reduction_factor: 2}\n"))
    summary = Search(spec, tmp_path / "out", {"jobs": 1}).run()
    assert summary["final"] is None and list(summary["halving"]["studies"]) == ["fold1", "fold2"]
    assert "Successive halving (first rung 1" in (tmp_path / "out" / "summary.md").read_text()


def test_if_it_wins_without_baselines_is_refused(tmp_path, data, capsys):
    """With no baseline the folds beat nothing: the final study would never run."""
    path = tmp_path / "none.yaml"
    path.write_text(SPEC.replace("baselines: {KCF: kcf}\n", ""), encoding="utf-8")
    Search(load_search_spec(path), tmp_path / "out")  # always: allowed
    assert cli.main(["search", str(path), "--out", str(tmp_path / "out"), "--final-study", "if_it_wins"]) != 0
    assert (f"{path}: final_study: if_it_wins needs baselines: with none, the folds beat nothing and the final "
            f"study would never run") in capsys.readouterr().err


def test_the_final_study_runs_after_the_verdict_when_the_folds_win(tmp_path, data, monkeypatch):
    """As if the folds had won: the verdict is reported before the final study's first trial,
    which then runs to its budget and writes best.yaml; --final-study overrides the spec."""
    spec = load_search_spec(spec_file(tmp_path, "final_study: if_it_wins\n"))
    out = tmp_path / "out"
    fresh = Search(spec, out)
    out.mkdir()
    fresh.check_record()  # as a run begins: search.json written, no trial yet
    assert ("  all: not begun (it runs only if the folds beat every baseline held out: final_study: if_it_wins)"
            in fresh.status())
    judge = study.judge
    monkeypatch.setattr(study, "judge", lambda search, studies: {**judge(search, studies),
                                                                 "beats_every_baseline": True})
    lines = []
    summary = Search(spec, out, {"jobs": 1}, report=lines.append).run()
    verdict = next(i for i, line in enumerate(lines) if line.startswith("held-out folds:"))
    assert lines[verdict].endswith("the final study follows")
    assert [line.split(" ")[0] for line in lines[verdict + 1:]] == ["all", "all"]
    assert summary["final"]["trial"] in (0, 1) and len(trials(out, "all")) == 2 and (out / "best.yaml").is_file()
    monkeypatch.undo()  # the folds lose again
    assert cli.main(["search", str(spec_file(tmp_path)), "--out", str(tmp_path / "cli"), "--jobs", "1",
                     "--final-study", "if_it_wins"]) == 0
    assert json.loads((tmp_path / "cli" / "summary.json").read_text())["final"] is None
