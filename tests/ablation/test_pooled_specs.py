"""Ablation and search specs on pooled datasets: ``dataset:`` as a list, or ``--root`` repeated;
the runs, the table and the statistics cover every root's sequences, and the records list them."""
from __future__ import annotations

import json
from pathlib import Path

import pytest
from test_ablation import write_otb

from dcfkit import cli
from dcfkit.ablation import load_spec
from dcfkit.ablation.spec_keys import data_record, data_text
from dcfkit.datasets import load_dataset
from dcfkit.errors import ConfigError

ABLATION = """
name: pooled
dataset:
  - {name: otb, root: a}
  - {name: dtb70, root: b}
variants:
  kcf: {config: kcf}
  kcf-wide: {config: kcf, overrides: {tracker.search_area_scale: 3.0}}
"""

SEARCH = """
name: pooled
dataset: otb
base: kcf
folds: 2
trials: 1
startup_trials: 1
space:
  tracker.search_area_scale: {float: [2.0, 3.0]}
"""


@pytest.fixture
def roots(tmp_path):
    """Two OTB-layout roots of synthetic sequences: a (seqA, seqB) and b (seqC)."""
    for i, (root, name) in enumerate((("a", "seqA"), ("a", "seqB"), ("b", "seqC"))):
        write_otb(tmp_path / root, name, seed=i, n_frames=6)
    return tmp_path / "a", tmp_path / "b"


def write(path: Path, text: str) -> Path:
    path.write_text(text, encoding="utf-8")
    return path


def test_a_spec_listing_datasets_pools_them_and_root_replaces_them_in_order(tmp_path, roots):
    a, b = roots
    spec = load_spec(write(tmp_path / "spec.yaml", ABLATION))
    assert spec.dataset == "otb+dtb70" and spec.root is None
    assert [(name, root) for name, root, _ in spec.pool] == [("otb", a), ("dtb70", b)]
    with pytest.raises(ConfigError, match=r"spec\.yaml: dataset lists 2 datasets but 3 --root were given"):
        load_spec(tmp_path / "spec.yaml", root=[b, a, a])
    swapped = load_spec(tmp_path / "spec.yaml", root=[b, a])
    assert [(name, root) for name, root, origin in swapped.pool] == [("otb", b), ("dtb70", a)]
    one = load_spec(write(tmp_path / "one.yaml", ABLATION.replace("dataset:\n  - {name: otb, root: a}\n"
                                                                  "  - {name: dtb70, root: b}", "dataset: otb")),
                    root=[a, b])
    assert one.dataset == "otb" and [s.name for s in one.load_sequences()] == ["seqA", "seqB", "seqC"]
    with pytest.raises(ConfigError, match=r"spec\.yaml: dataset\[1\]\.name: unknown dataset 'dtb71'"):
        load_spec(write(tmp_path / "spec.yaml", ABLATION.replace("dtb70", "dtb71")))


def test_an_ablation_on_two_roots_runs_and_records_all_their_sequences(tmp_path, roots, capsys):
    a, b = roots
    spec = write(tmp_path / "spec.yaml", ABLATION.replace("dtb70", "otb"))
    out = tmp_path / "out"
    assert cli.main(["ablate", str(spec), "--out", str(out), "--dry-run"]) == 0
    listed = capsys.readouterr().out.splitlines()
    assert [line.split()[-1] for line in listed[:-1]] == ["seqA", "seqB", "seqC"] * 2
    assert listed[-1] == "6 jobs, 6 distinct runs"
    loaded = load_spec(spec)
    assert data_record(loaded) == {"dataset": ["otb", "otb"], "root": [str(a), str(b)]}  # summary.json's
    assert data_text(loaded) == f"otb at {a}, otb at {b}"  # report.html's
    single = load_spec(write(tmp_path / "one.yaml", ABLATION.split("dataset:")[0] + "dataset: otb\nvariants:"
                             + ABLATION.split("variants:")[1]), root=a)
    assert data_record(single) == {"dataset": "otb", "root": str(a)} and data_text(single) == f"otb at {a}"


def test_a_search_on_two_roots_folds_and_scores_all_their_sequences(tmp_path, roots):
    pytest.importorskip("optuna")
    a, b = roots
    write_otb(b, "seqD", seed=3, n_frames=6)
    spec, out = write(tmp_path / "s.yaml", SEARCH), tmp_path / "out"
    assert cli.main(["search", str(spec), "--out", str(out), "--jobs", "1", "--root", str(a), "--root", str(b)]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["dataset"] == ["otb", "otb"] and summary["sequences"] == ["seqA", "seqB", "seqC", "seqD"]
    assert sorted(n for fold in summary["folds"] for n in fold["held_out"]) == summary["sequences"]
    assert set(summary["held_out"]["per_sequence"]) == {"seqA", "seqB", "seqC", "seqD"}
    assert json.loads((out / "search.json").read_text())["fingerprint"]["dataset"] == ["otb", "otb"]
    assert [s.name for s in load_dataset("otb", b)] == ["seqC", "seqD"]  # b alone: what the search added to a
