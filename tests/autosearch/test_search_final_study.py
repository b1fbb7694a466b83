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


def spec_file(tmp_path, extra: str = ""):
    path = tmp_path / "s.yaml"
    path.write_text(SPEC + extra, encoding="utf-8")
    return path


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
    assert cli.main(["search", str(spec_file(tmp_path, "final_study: if_it_wins\n")), "--out", str(out),
                     "--jobs", "1"]) == 0
    printed = capsys.readouterr()
    whole, skipped = (json.loads((d / "summary.json").read_text()) for d in (tmp_path / "always", out))
    assert {k: skipped[k] for k in VERDICT} == {k: whole[k] for k in VERDICT}
    assert not whole["beats_every_baseline"] and whole["final"]["trial"] in (0, 1) and len(trials(tmp_path / "always",
                                                                                                  "all")) == 2
    assert skipped["final"] is None and skipped["final_study"] == "if_it_wins" and trials(out, "all") == []
    assert not (out / "best.yaml").exists()
    assert "Final study: not run (`final_study: if_it_wins`, and the folds lost); no best.yaml." in printed.out
    assert "0 of 1 baselines beaten: the final study is skipped (final_study: if_it_wins)" in printed.err
    assert cli.main(["search", str(spec), "--out", str(out), "--status"]) == 0
    status = capsys.readouterr().out.splitlines()
    assert "  all: skipped: the folds lost held out (final_study: if_it_wins)" in status
    assert status[-1] == "summary.md: written"


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
