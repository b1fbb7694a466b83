"""dcfkit search against hostile records and specs (issue 37's own attacker's review): a resume
stands only on records this search wrote, a spec's `when` chains and names are checked whole.

One small search (KCF, one float dimension, 2 folds of 4 synthetic sequences) is run once and
copied per case."""
from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import pytest
from test_ablation import write_otb

from dcfkit import cli
from dcfkit.autosearch import Search, load_search_spec
from dcfkit.autosearch.study import sample
from dcfkit.autosearch.summary import summary_lines
from dcfkit.errors import ConfigError

pytest.importorskip("optuna")

SPEC = """
name: small
dataset: {name: otb, root: data}
base: kcf
folds: 2
trials: 2
baselines: {KCF: kcf}
space:
  solver.sigma: {float: [0.3, 0.7]}
"""

NESTED = """
name: nested
dataset: {name: otb}
base: strcf
space:
  label: {choice: {gaussian: {name: gaussian}, repressed: {name: distractor_repressed}}}
  label.top_n: {choice: [10, 30], when: {label: repressed}}
  label.mu: {float: [0.05, 1.0], when: {label.top_n: '10'}}
"""


@pytest.fixture(scope="module")
def searched(tmp_path_factory) -> Path:
    """A folder with ``data``, ``s.yaml`` and ``out``: the spec's search, run to its end."""
    folder = tmp_path_factory.mktemp("searched")
    for i, name in enumerate(("seqA", "seqB", "seqC", "seqD")):
        write_otb(folder / "data", name, seed=i, n_frames=8)
    (folder / "s.yaml").write_text(SPEC, encoding="utf-8")
    Search(load_search_spec(folder / "s.yaml"), folder / "out", {"jobs": 1}).run()
    return folder


@pytest.fixture
def copy(searched, tmp_path) -> Path:
    """A copy of the searched folder, the copy's spec reading the copy's data."""
    shutil.copytree(searched, tmp_path / "c")
    return tmp_path / "c"


@pytest.mark.parametrize("record", ["missing", "[]", "truncated"])
def test_trials_without_a_readable_search_record_are_refused(copy, capsys, record):
    """Without search.json nothing shows the trials are this search's: a search of another seed,
    whose folds differ, used to take them, so a held-out sequence chose the config."""
    path = copy / "out/search.json"
    text = path.read_text()
    path.unlink() if record == "missing" else path.write_text("[]" if record == "[]" else text[:40])
    (copy / "s.yaml").write_text(SPEC.replace("folds: 2", "folds: 2\nseed: 5"))
    summary = (copy / "out/summary.json").read_bytes()
    assert cli.main(["search", str(copy / "s.yaml"), "--out", str(copy / "out"), "--jobs", "1"]) != 0
    err = capsys.readouterr().err
    state = "missing" if record == "missing" else "not a search record as dcfkit writes it"
    assert err.startswith(f"dcfkit search: error: {path} is {state}, yet {copy / 'out/trials'} holds trial records")
    assert err.rstrip().endswith(f"remove {copy / 'out/trials'} to start again") and err.count("\n") == 1
    assert (copy / "out/summary.json").read_bytes() == summary


def _other_study(rec: dict, out: Path) -> str:
    """Trial 1 of fold 2, whose training sequences are fold 1's held-out ones."""
    return (out / "trials/fold2/0001.json").read_text()


def _edited(**change):
    return lambda rec, out: json.dumps({**rec, **change})


EDITS = {
    "truncated": (lambda rec, out: json.dumps(rec)[:40], "not a JSON object"),
    "value text": (_edited(value="abc"), "value: 'abc' is not the mean AUC of its scores"),
    "value null": (_edited(value=None), "value: None is not the mean AUC"),
    "value raised": (_edited(value=0.99), "value: 0.99 is not the mean AUC"),
    "no config": (lambda rec, out: json.dumps({k: v for k, v in rec.items() if k != "config"}),
                  "config: not the config its params make"),
    "params a list": (_edited(params=[1]), "params: expected a mapping of the space's keys, got [1]"),
    "params unknown": (_edited(params={"bogus": 1}), "params: 'bogus' is not a key of the space"),
    "params out of range": (_edited(params={"solver.sigma": 5.0}),
                            "params.solver.sigma: 5.0 is not a value its dimension takes"),
    "params as text": (_edited(params={"solver.sigma": "0.5"}),
                       "params.solver.sigma: '0.5' is not a value its dimension takes"),
    "params empty": (_edited(params={}), "params: expected values for ['solver.sigma']"),
    "number": (_edited(number=0), "number: expected 1, got 0"),
    "key": (_edited(key="0" * 16), "key: not its config's run key"),
    "other study": (_other_study, "scores: expected those of this study's training sequences ['seqA', 'seqD']"),
}


@pytest.mark.parametrize("edit, fault", EDITS.values(), ids=list(EDITS))
def test_a_damaged_or_edited_trial_record_is_redone_with_a_warning_naming_it(copy, caplog, edit, fault):
    """Each edit used to resume silently or die in a traceback (TypeError, KeyError,
    AttributeError, Optuna's ValueError) naming no file; now the record is run again, to the
    same values, and the warning names the file and what is wrong. Trial 1 is edited: trial 0
    is the base (warm start), whose own case follows."""
    path = copy / "out/trials/fold1/0001.json"
    original = {path: path.read_bytes()}
    summary = json.loads((copy / "out/summary.json").read_text())
    path.write_text(edit(json.loads(path.read_text()), copy / "out"))
    with caplog.at_level("WARNING", logger="dcfkit.autosearch.study"):
        Search(load_search_spec(copy / "s.yaml"), copy / "out", {"jobs": 1}).run()
    warned = [r.getMessage() for r in caplog.records if r.levelname == "WARNING"]
    assert len(warned) == 1 and warned[0].startswith(f"{path} is not a trial record as dcfkit writes it ({fault}")
    assert warned[0].endswith("trial 1 of fold1 is run again, and the trials after it")
    assert {p: p.read_bytes() for p in original} == original
    assert {**json.loads((copy / "out/summary.json").read_text()), "spec": summary["spec"]} == summary


def test_a_search_moved_with_only_its_records_resumes_without_running_a_trial(searched, tmp_path):
    """search.json and trials/ are a search's whole state (docs/search.md, "Moving a search"):
    moved to another folder, its data under another path, it runs no trial again and ends on the
    same summary; only the runs the summary scores are tracked again."""
    moved = tmp_path / "elsewhere"
    shutil.copytree(searched / "data", moved / "frames")
    (moved / "s.yaml").write_text(SPEC.replace("root: data", "root: frames"), encoding="utf-8")
    (moved / "out").mkdir()
    shutil.copy(searched / "out/search.json", moved / "out")
    shutil.copytree(searched / "out/trials", moved / "out/trials")
    trials = {p.relative_to(moved / "out"): p.read_bytes() for p in (moved / "out/trials").rglob("*.json")}
    said: list[str] = []
    Search(load_search_spec(moved / "s.yaml"), moved / "out", {"jobs": 1}, report=said.append).run()
    assert not [line for line in said if " trial " in line], said
    assert {p.relative_to(moved / "out"): p.read_bytes() for p in (moved / "out/trials").rglob("*.json")} == trials
    summary = json.loads((searched / "out/summary.json").read_text())
    assert {**json.loads((moved / "out/summary.json").read_text()), "spec": summary["spec"]} == summary


def test_status_says_a_damaged_record_would_be_run_again_and_runs_nothing(copy, caplog):
    """--status reads the records as a resume would, but runs nothing: its warning must not say
    the trial is run again."""
    path = copy / "out/trials/fold1/0001.json"
    path.write_text(EDITS["key"][0](json.loads(path.read_text()), copy / "out"))
    before = {p: p.read_bytes() for p in (copy / "out").rglob("*") if p.is_file()}
    with caplog.at_level("WARNING", logger="dcfkit.autosearch.study"):
        lines = Search(load_search_spec(copy / "s.yaml"), copy / "out", {"jobs": 1}).status()
    warned = [r.getMessage() for r in caplog.records if r.levelname == "WARNING"]
    assert len(warned) == 1 and warned[0].endswith("trial 1 of fold1 would be run again, and the trials after it")
    assert lines and {p: p.read_bytes() for p in (copy / "out").rglob("*") if p.is_file()} == before


def test_a_trial_0_that_is_not_the_base_is_redone_as_the_base(copy, caplog):
    """Trial 1's record put in trial 0's place: sampled values, where the base's stand."""
    path = copy / "out/trials/fold1/0000.json"
    base = path.read_bytes()
    path.write_text(json.dumps({**json.loads((copy / "out/trials/fold1/0001.json").read_text()), "number": 0}))
    with caplog.at_level("WARNING", logger="dcfkit.autosearch.study"):
        Search(load_search_spec(copy / "s.yaml"), copy / "out", {"jobs": 1}).run()
    warned = [r.getMessage() for r in caplog.records if r.levelname == "WARNING"]
    assert len(warned) == 1 and "(params: expected the base config's, {'solver.sigma': 0.5})" in warned[0]
    assert path.read_bytes() == base


def test_a_chain_of_whens_is_followed_when_the_spec_is_read(tmp_path):
    """label.mu is sampled under label.top_n '10', itself only under label 'repressed': checked
    under label 'gaussian' alone it used to be refused; each label a when lists is checked."""
    path = tmp_path / "s.yaml"
    path.write_text(NESTED)
    spec = load_search_spec(path)
    sampled = [sample(spec, "all", n, []) for n in range(8)]
    assert any("label.mu" in s for s in sampled) and any(s["label"] == "gaussian" for s in sampled)
    for s in sampled:
        assert spec.config(s)["label"]["name"] == ("gaussian" if s["label"] == "gaussian" else "distractor_repressed")
    path.write_text(NESTED.replace("when: {label: repressed}", "when: {label: [repressed, gaussian]}"))
    with pytest.raises(ConfigError, match=re.escape(f"{path}: space.label.top_n: with the value 10 under "
                                                    f"label='gaussian': ")):
        load_search_spec(path)
    path.write_text(NESTED.replace("when: {label.top_n: '10'}", "when: {label.top_n: '10', label: gaussian}"))
    with pytest.raises(ConfigError, match=re.escape(f"{path}: space.label.mu.when: never holds")):
        load_search_spec(path)


@pytest.mark.parametrize("old, new, message", [
    ("{KCF: kcf}", "{1: kcf, '1': dsst}", "baselines: two baseline names read as '1': give distinct baseline names"),
    ("{KCF: kcf}", "{'': kcf}", "baselines: '' is not a name: give each baseline a name"),
    ("{KCF: kcf}", "{null: kcf, KCF: kcf}", "baselines: None is not a name"),
    ("{KCF: kcf}", '{"K\\nCF": kcf}', "baselines: the baseline name 'K\\nCF' has a line break or control character"),
    ("name: small", 'name: "small\\n| injected |"', "name: the name 'small\\n| injected |' has a line break"),
    ("{float: [0.3, 0.7]}", '{choice: {"a\\rb": 0.3, c: 0.5}}',
     "space.solver.sigma.choice: the label 'a\\rb' has a line break"),
])
def test_a_baseline_or_name_that_cannot_stand_alone_is_refused(tmp_path, old, new, message):
    """Baselines 1 and '1' used to become one, the second's scores under the first's name, and
    the search judged without the first; an empty or null name became '' or 'None'; a line break
    in a name wrote rows of its own into summary.md."""
    path = tmp_path / "s.yaml"
    path.write_text(SPEC.replace(old, new))
    with pytest.raises(ConfigError, match=re.escape(f"{path}: {message}")):
        load_search_spec(path)


def test_summary_md_keeps_each_name_in_its_cell(searched):
    """A sequence folder, label or baseline name holding `|` used to add columns to summary.md's
    tables, and a line break in the name rows of its own."""
    summary = json.loads((searched / "out/summary.json").read_text())
    plain = summary_lines(summary)
    summary["name"] = "small\n| x |"
    summary["folds"][0]["held_out"] = ["seq|B", "seqC"]
    summary["folds"][0]["params"] = {"label": "a|b", "solver.sigma": 0.5}
    summary["baselines"]["K|CF"] = summary["baselines"].pop("KCF")
    summary["comparisons"]["K|CF"] = summary["comparisons"].pop("KCF")
    hostile = summary_lines(summary)
    assert len(hostile) == len(plain) and hostile[0] == "# Search small\\n| x |"
    for before, after in zip(plain[1:], hostile[1:]):  # the tables' rows: as many cells as before
        assert len(re.findall(r"(?<!\\)\|", after)) == before.count("|")
    assert any(line.startswith("| K\\|CF | ") for line in hostile)


def test_a_malformed_scheduler_address_is_one_line_before_any_trial(tmp_path, capsys):
    assert cli.main(["search", "missing.yaml", "--out", str(tmp_path / "out"), "--scheduler", "garbage://x"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("dcfkit search: error: dask scheduler 'garbage://x': unknown scheme") and err.count("\n") == 1
    assert not (tmp_path / "out").exists()
