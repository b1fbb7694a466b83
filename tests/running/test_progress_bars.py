"""Progress bars only on a terminal: a log file or pipe gets no ``\\r``-redrawn lines (as ``track``)."""
from __future__ import annotations

import io
import sys
import types

import pytest
from test_evaluation import CONFIG, Counter, seqs  # noqa: F401  (seqs: a fixture)

from dcfkit.ablation import run as ablation_run
from dcfkit.running import runner
from dcfkit.store import provenance
from dcfkit.running.evaluation import run_one_pass


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def ablate(tmp_path, seqs):  # noqa: F811
    """ablate's runner on three fake runs (its bar counts runs)."""
    key = provenance.run_key(CONFIG)
    tasks = [runner.RunTask(CONFIG, s, tmp_path / "abl", key, Counter()) for s in seqs]
    (tmp_path / "abl").mkdir(exist_ok=True)
    result = {"done": [], "failed": {}}
    ablation_run._run(types.SimpleNamespace(name="spec"), result, tasks, len(tasks), {key: ["v"]}, 1, "local", None,
                      True, provenance.dcfkit_version())
    assert len(result["done"]) == len(seqs)


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
