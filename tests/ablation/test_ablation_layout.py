"""An ablation's runs in eval's layout, OUT/<variant>/[<experiment>/]: `report` and `compare`
read them and score them as the ablation's summary does; variants of one config run once;
runs in the layout of dcfkit <= 0.10 (OUT/jobs/) are warned of and never reused."""
from __future__ import annotations

import json

import pytest
from test_ablation import data, write_spec  # noqa: F401  (data: a fixture)
from test_evaluation import DriftTracker

from dcfkit import cli
from dcfkit.ablation import expand, load_spec, run_ablation
from dcfkit.running import runner

TWO_KCFS = """
name: two
dataset: {name: otb, root: data}
sequences: [seqA, seqB]
variants:
  kcf: {config: kcf}
  wide: {config: kcf, overrides: {tracker.search_area_scale: 3.0}}
"""


def scores(rows: list[dict], name: str) -> dict:
    return {row[name]: (row["auc"], row["precision"]) for row in rows}


def test_an_ablations_runs_are_compared_and_reported_as_its_summary_scores_them(tmp_path, data, capsys):  # noqa: F811
    spec, out = write_spec(tmp_path / "spec.yaml", TWO_KCFS), tmp_path / "out"
    root = ["--dataset", "otb", "--root", str(data)]
    assert cli.main(["ablate", str(spec), "--out", str(out), "--jobs", "1", "--no-progress"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["folders"] == {"kcf": "kcf", "wide": "wide"}
    capsys.readouterr()
    assert cli.main(["compare", str(out / "wide"), str(out / "kcf"), *root]) == 0
    printed = capsys.readouterr().out
    assert "wide (RESULTS): " in printed and "kcf (REFERENCE): " in printed and "left out: none" in printed
    assert cli.main(["report", str(out), *root, "--html"]) == 0
    report = json.loads((tmp_path / "out_report" / "report.json").read_text())
    assert scores(report["overall"], "tracker") == scores(summary["overall"], "variant")  # the same runs, scores
    assert (tmp_path / "out_report" / "report.html").is_file()


def test_a_tre_ablation_is_reported_by_report_as_by_its_summary(tmp_path, capsys):
    from test_ablation import write_otb  # the data of TRE: long enough for its 20 starts

    for i, name in enumerate(("seqA", "seqB")):
        write_otb(tmp_path / "data", name, seed=i, n_frames=22)
    spec = write_spec(tmp_path / "spec.yaml", TWO_KCFS + "experiment: tre\n")
    out = tmp_path / "out"
    assert cli.main(["ablate", str(spec), "--out", str(out), "--jobs", "1", "--no-progress"]) == 0
    assert cli.main(["report", str(out), "--dataset", "otb", "--root", str(tmp_path / "data"), "--experiment", "tre",
                     "--html"]) == 0
    report = json.loads((tmp_path / "out_report" / "tre" / "report.json").read_text())
    summary = json.loads((out / "summary.json").read_text())
    assert scores(report["overall"], "tracker") == scores(summary["overall"], "variant")
    assert (tmp_path / "out_report" / "tre" / "report.html").is_file()


@pytest.fixture
def made(monkeypatch):
    """The trackers the runs make, counted (fake ones: the count is the point)."""
    configs = []
    monkeypatch.setattr(runner, "_warm_up", lambda task: None)  # no throw-away tracker: the count is the runs'
    monkeypatch.setattr(runner, "load_dcfkit_tracker", lambda config: configs.append(config) or DriftTracker(config))
    return configs


def test_variants_of_one_config_run_once_and_each_folder_holds_the_runs(tmp_path, data, made):  # noqa: F811
    spec = load_spec(write_spec(tmp_path / "spec.yaml", """
dataset: {name: otb, root: data}
sequences: [seqA, seqB]
variants:
  one: {config: kcf}
  two: {config: kcf, description: "the same parameters, another name"}
  three: {config: kcf, overrides: {tracker.search_area_scale: 3.0}}
grid: {base: one, parameters: {tracker.search_area_scale: [3.0, 2.5]}}
"""))
    out = tmp_path / "out"
    res = run_ablation(spec, out, jobs=1, progress=False)
    keys = {j.variant: j.key for j in expand(spec)}
    assert keys["one"] == keys["two"] and keys["three"] == keys["tracker.search_area_scale=3.0"]
    assert len(made) == 2 * len(set(keys.values())) == res["runs"] == len(res["done"])  # one run a key
    for a, b in (("one", "two"), ("three", "tracker.search_area_scale=3.0")):
        for name in ("seqA.txt", "seqA.json", "seqB.txt", "seqB.json"):
            assert (out / a / name).read_bytes() == (out / b / name).read_bytes()
    rows = {r["variant"]: (r["auc"], r["precision"], r["failed"]) for r in res["summary"]["overall"]}
    assert rows["one"] == rows["two"] and rows["three"] == rows["tracker.search_area_scale=3.0"]
    again = run_ablation(spec, out, jobs=1, progress=False)
    assert len(made) == 2 * len(set(keys.values())) and again["done"] == []


def test_runs_in_the_old_layout_are_warned_of_once_and_not_reused(tmp_path, data, made, caplog):  # noqa: F811
    spec = load_spec(write_spec(tmp_path / "spec.yaml", TWO_KCFS))
    out = tmp_path / "out"
    key = expand(spec)[0].key
    old = out / "jobs" / "otb" / key
    old.mkdir(parents=True)
    (old / "seqA.txt").write_text("1.000,2.000,3.000,4.000\n")  # as dcfkit 0.10 stored a run
    with caplog.at_level("WARNING"):
        res = run_ablation(spec, out, jobs=1, progress=False)
    said = [r.getMessage() for r in caplog.records if "old layout" in r.getMessage()]
    assert len(said) == 1 and "dcfkit <= 0.10" in said[0] and f"dcfkit report {out / 'jobs'}/<dataset>" in said[0]
    assert len(made) == 4 and len(res["done"]) == 4 and (old / "seqA.txt").is_file()  # recomputed, the old kept
    assert (out / "kcf" / "seqA.json").is_file()
