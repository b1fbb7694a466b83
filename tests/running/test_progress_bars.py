"""Progress bars only on a terminal: a log file or pipe gets no ``\\r``-redrawn lines (as ``track``)."""
from __future__ import annotations

import io
import sys

import pytest
from test_evaluation import CONFIG, Counter, seqs  # noqa: F401  (seqs: a fixture)

from dcfkit.running.evaluation import run_one_pass
from dcfkit.running.plan import Entry, RunPlan
from dcfkit.running.progress import RunBar


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def ablate(tmp_path, seqs):  # noqa: F811
    """ablate's bar (it counts runs) on a plan of three fake runs."""
    plan = RunPlan([Entry("v", CONFIG, Counter())], seqs, "ope", tmp_path / "abl")
    plan.run("dcfkit ablate", progress=RunBar("spec", True, lambda shared: ["v"]))
    assert len(plan.entries[0].done) == len(seqs)


def evaluate(tmp_path, seqs):  # noqa: F811
    run_one_pass(CONFIG, seqs, tmp_path / "out", make_tracker=Counter(), progress=True)


@pytest.mark.parametrize("command", [evaluate, ablate])
def test_no_bar_when_stderr_is_not_a_terminal(tmp_path, seqs, monkeypatch, command):  # noqa: F811
    log = io.StringIO()  # what `dcfkit eval ... 2> log.txt` writes to
    monkeypatch.setattr(sys, "stderr", log)
    command(tmp_path, seqs)
    assert "\r" not in log.getvalue()


@pytest.mark.parametrize("command", [evaluate, ablate])
def test_a_bar_on_a_terminal(tmp_path, seqs, monkeypatch, command):  # noqa: F811
    screen = Terminal()
    monkeypatch.setattr(sys, "stderr", screen)
    command(tmp_path, seqs)
    assert "\r" in screen.getvalue() and "100%" in screen.getvalue()
