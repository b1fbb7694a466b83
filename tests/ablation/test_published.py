"""Published results in an ablation spec: scored and compared beside the variants, never run."""
from __future__ import annotations

import json

import pytest
from test_ablation import data, write_spec  # noqa: F401  (data: the fixture)

from dcfkit import cli
from dcfkit.ablation import load_spec
from dcfkit.datasets import load_dataset
from dcfkit.errors import ConfigError

SPEC = """
name: with_published
dataset: {name: otb, root: data}
variants:
  kcf: {config: kcf}
published:
  the truth: truth
"""


def write_truth(folder, root, drop=()):
    """Result files holding the ground truth itself (a perfect tracker), 1-based."""
    folder.mkdir()
    for seq in load_dataset("otb", root):
        if seq.name not in drop:
            (folder / f"{seq.name}.txt").write_text("".join("%g,%g,%g,%g\n" % tuple(b + [1, 1, 0, 0])
                                                           for b in seq.ground_truth))


def test_published_results_are_scored_beside_the_variants_without_being_run(tmp_path, data, capsys):  # noqa: F811
    write_truth(tmp_path / "truth", data, drop=("seqD",))
    spec = write_spec(tmp_path / "spec.yaml", SPEC)
    assert load_spec(spec).published == (("the truth", (tmp_path / "truth").resolve()),)
    out = tmp_path / "out"
    assert cli.main(["ablate", str(spec), "--out", str(out), "--jobs", "1", "--no-progress"]) == 0
    printed = capsys.readouterr().out
    assert "4 jobs (4 distinct runs): 4 run" in printed  # kcf on four sequences; nothing for the truth
    summary = json.loads((out / "summary.json").read_text())
    rows = {r["variant"]: r for r in summary["overall"]}
    assert list(rows) == ["kcf", "the truth"] and rows["the truth"]["key"] == "published"
    assert rows["the truth"]["failed"] == 1  # seqD: no file, scored as a failure and counted
    per = {(r["variant"], r["sequence"]): r for r in summary["per_sequence"]}
    assert per["the truth", "seqA"]["status"] == "published" and per["the truth", "seqD"]["status"] == "missing"
    assert per["the truth", "seqA"]["auc"] == pytest.approx(20 / 21) and per["the truth", "seqD"]["auc"] == 0
    assert set(summary["statistics"]["differences"]) == {"the truth"}  # compared with the first variant
    assert {j["variant"] for j in summary["jobs"]} == {"kcf"}
    page = (out / "report.html").read_text()
    assert "the truth" in page and "published results:" in page


@pytest.mark.parametrize("extra, message", [
    ("published:\n  kcf: truth\n", "published.kcf: a variant has that name"),
    ("published:\n  other: nowhere\n", r"published.other: .*nowhere is not a folder \(relative paths are the spec's\)"),
    ("published: [truth]\n", "published: expected a mapping of names to result folders"),
    ("experiment: tre\npublished:\n  other: truth\n", "published: published results are one-pass results; the "
                                                       "spec's experiment is tre"),
])
def test_bad_published_entries_name_the_key(tmp_path, extra, message):
    (tmp_path / "truth").mkdir()
    spec = write_spec(tmp_path / "spec.yaml", "name: x\ndataset: otb\nvariants:\n  kcf: {config: kcf}\n" + extra)
    with pytest.raises(ConfigError, match=message):
        load_spec(spec)
