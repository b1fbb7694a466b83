"""The search records kept in docs/searches/: each summary is the one its trials give, and its
``summary.md`` is what this version renders from its ``summary.json`` (so docs/results.md,
which quotes them, quotes the record)."""
from __future__ import annotations

import json
from pathlib import Path

import pytest

from dcfkit.autosearch.summary import best, summary_lines

SEARCHES = sorted(p.parent for p in (Path(__file__).parents[2] / "docs" / "searches").glob("*/summary.json"))


def _trials(folder: Path, study: str) -> list[dict]:
    return [json.loads(p.read_text()) for p in sorted((folder / "trials" / study).glob("*.json"))]


@pytest.mark.parametrize("folder", SEARCHES, ids=[p.name for p in SEARCHES])
def test_summary_md_is_rendered_from_summary_json(folder):
    summary = json.loads((folder / "summary.json").read_text())
    assert (folder / "summary.md").read_text() == "\n".join(summary_lines(summary)) + "\n"


@pytest.mark.parametrize("folder", SEARCHES, ids=[p.name for p in SEARCHES])
def test_each_folds_choice_is_its_studys_best_trial(folder):
    summary = json.loads((folder / "summary.json").read_text())
    assert len(summary["folds"]) >= 2
    for fold in summary["folds"]:
        study = f"fold{fold['fold']}"
        records = _trials(folder, study)
        assert len(records) == summary["trials_per_study"]
        chosen = best(records, study)
        assert (fold["trial"], fold["params"]) == (chosen["number"], chosen["params"])
        assert fold["training_auc"] == pytest.approx(chosen["value"], rel=0, abs=1e-12)
        assert not set(fold["held_out"]) & set(chosen["scores"])  # chosen without its held-out sequences
