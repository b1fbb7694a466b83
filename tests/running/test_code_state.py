"""The run key follows the code that computes boxes: an edited tracker file gets new results at
the same version; an edited report or command line keeps them."""
from __future__ import annotations

import json
import shutil

import pytest
from test_evaluation import CONFIG, Counter, seqs  # noqa: F401  (seqs: a fixture)

from dcfkit.analysis.report_html.provenance import describe_sources
from dcfkit.store import code_state, provenance
from dcfkit.store.code_state import code_digest
from dcfkit.running.evaluation import run_one_pass
from dcfkit.store.provenance import package_source, run_key


@pytest.fixture(scope="module")
def tree(tmp_path_factory):
    """A copy of the dcfkit package this test runs (a second source tree of the same version)."""
    copy = tmp_path_factory.mktemp("trees") / "dcfkit"
    shutil.copytree(code_state.PACKAGE, copy, ignore=shutil.ignore_patterns("__pycache__"))
    return copy


def edited(tree, relative: str, change):
    """The digest of ``tree`` with ``relative`` changed by ``change(text)``; the file restored after."""
    path = tree / relative
    before = path.read_bytes()
    try:
        path.write_bytes(change(before))
        return code_digest(tree)
    finally:
        path.write_bytes(before)


def test_the_same_source_has_the_same_digest(tree):
    assert code_digest(tree) == code_state.box_code() == code_digest(code_state.PACKAGE)


@pytest.mark.parametrize("relative", ["tracker/tracker.py", "components/solvers/base.py", "numerics/fft.py",
                                      "config/tracker_params.py", "experiments/loop.py", "data/uav123_sequences.tsv"])
def test_box_code_changes_the_key(tree, relative):
    same = code_digest(tree)
    changed = edited(tree, relative, lambda text: text + b"\n# one more line\n")
    assert changed != same
    config = {"name": "x", "drift": 1.0}
    assert run_key(config, "0.9.0", code=changed) != run_key(config, "0.9.0", code=same)


@pytest.mark.parametrize("relative", ["cli/parser.py", "analysis/report.py", "analysis/report_html/report.css",
                                      "store/results.py", "store/provenance.py", "ablation/spec.py"])
def test_code_that_changes_no_box_keeps_the_key(tree, relative):
    assert edited(tree, relative, lambda text: text + b"\n/* one more line */\n") == code_digest(tree)


def test_line_endings_and_a_new_module(tree):
    same = code_digest(tree)
    assert edited(tree, "tracker/geometry.py", lambda text: text.replace(b"\n", b"\r\n")) == same  # a Windows checkout
    extra = tree / "components" / "new_solver.py"
    extra.write_text("X = 1\n")
    try:
        assert code_digest(tree) != same  # new code is box code unless NOT_BOX_CODE says otherwise
    finally:
        extra.unlink()


def test_a_built_package_reads_the_state_its_build_recorded(tmp_path):
    package = tmp_path / "site" / "pkg"
    package.mkdir(parents=True)
    assert package_source("no-such-distribution", str(package)) is None
    (package / "_source.json").write_text(json.dumps({"commit": "ab" * 20, "dirty": True}))
    package_source.cache_clear()
    assert package_source("no-such-distribution", str(package)) == {"commit": "ab" * 20, "dirty": True}
    (package / "_source.json").write_text("[1, 2]")  # damaged: nothing recorded
    package_source.cache_clear()
    assert package_source("no-such-distribution", str(package)) is None
    package_source.cache_clear()


def test_edited_box_code_reruns_and_the_sidecar_says_so(tmp_path, seqs, monkeypatch):  # noqa: F811
    out = tmp_path / "out"
    first = run_one_pass(CONFIG, seqs, out, make_tracker=Counter(), progress=False)
    meta = json.loads((out / "drift" / "a.json").read_text())
    assert meta["source"]["dcfkit"]["code"] == code_state.box_code()
    assert f"code {code_state.box_code()}" in describe_sources(meta["source"])
    again = run_one_pass(CONFIG, seqs, out, make_tracker=Counter(), progress=False)
    assert again["skipped"] == first["done"] and not again["done"]
    monkeypatch.setattr(provenance, "box_code", lambda: "0123456789abcdef")  # a tracker file edited since
    edited_run = run_one_pass(CONFIG, seqs, out, make_tracker=Counter(), progress=False)
    assert edited_run["done"] == first["done"] and not edited_run["skipped"]
    assert edited_run["run_key"] != first["run_key"]


def test_sidecars_without_a_code_digest_are_rerun(tmp_path, seqs):  # noqa: F811
    """Results of dcfkit 0.9.0, whose keys had no digest: the code that made them is unknown, so
    they are recomputed (and still read by report: the sidecar's key is not checked there)."""
    out = tmp_path / "out"
    run_one_pass(CONFIG, seqs, out, make_tracker=Counter(), progress=False)
    for sidecar in (out / "drift").glob("*.json"):
        meta = json.loads(sidecar.read_text())
        meta["run_key"] = old_key(CONFIG)
        meta["source"] = {"dcfkit": None}
        sidecar.write_text(json.dumps(meta))
    assert describe_sources({"dcfkit": None}) == "dcfkit: no git commit recorded (a release)"
    assert sorted(provenance_of(out)) == ["a", "b", "c"]
    assert run_one_pass(CONFIG, seqs, out, make_tracker=Counter(), progress=False)["done"] == ["a", "b", "c"]


def old_key(config) -> str:
    """dcfkit 0.9.0's run key: config, version, no code digest."""
    import hashlib

    payload = {"config": {k: v for k, v in config.items() if k not in ("name", "description")},
               "dcfkit": provenance.dcfkit_version()}
    return hashlib.sha256(json.dumps(payload, sort_keys=True, separators=(",", ":")).encode()).hexdigest()[:16]


def provenance_of(out):
    from dcfkit.store.results import load_results

    return load_results(out, "drift", ["a", "b", "c"])
