"""Module paths the docs of 0.6 showed still import for one release, with a DeprecationWarning,
as the very module of their new home."""
from __future__ import annotations

import importlib
import sys
from pathlib import Path

import pytest

import dcfkit

OLD_NAMES = sorted(p.stem for p in (Path(dcfkit.__file__).parent / "_moved").glob("*.py") if p.stem != "__init__")


def test_every_module_the_old_docs_showed_has_its_old_name():
    shown = {"tracking", "results", "solvers", "regularizers", "labels", "features", "search", "scale", "report",
             "evaluation", "baselines", "synthetic", "platforms", "compare", "runner", "report_html"}
    assert shown <= set(OLD_NAMES)


@pytest.mark.parametrize("old", OLD_NAMES)
def test_an_old_name_warns_and_is_the_new_module(old, monkeypatch):
    monkeypatch.delitem(sys.modules, f"dcfkit.{old}", raising=False)
    with pytest.warns(DeprecationWarning, match=rf"dcfkit\.{old} moved to dcfkit\.\w+\.\w+ in dcfkit 0\.7"):
        module = importlib.import_module(f"dcfkit.{old}")
    assert module.__name__ != f"dcfkit.{old}" and sys.modules[module.__name__] is module


def test_the_names_old_code_imported_are_the_same_objects(monkeypatch):
    for old in ("labels", "results", "tracking"):
        monkeypatch.delitem(sys.modules, f"dcfkit.{old}", raising=False)
    with pytest.warns(DeprecationWarning):
        from dcfkit.labels import Detection, Label
        from dcfkit.results import ResultStore
        from dcfkit.tracking import track
    from dcfkit.components.labels.base import Detection as new_detection
    from dcfkit.components.labels.base import Label as new_label
    from dcfkit.running.results import ResultStore as new_store
    from dcfkit.running.tracking import track as new_track
    assert (Detection, Label, ResultStore, track) == (new_detection, new_label, new_store, new_track)
