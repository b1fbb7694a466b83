"""dcfkit compare --experiment tre/sre: each sequence's runs compared, its scores pooled as
dcfkit report pools them (checked against the report's own scoring), IoU and the first
divergence over its runs (checked by brute force), incomplete sequences left out."""
from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from test_ablation import write_otb

from dcfkit import cli
from dcfkit.analysis.compare import compare_folders, first_divergence, series_iou
from dcfkit.analysis.report import score_and_write
from dcfkit.datasets import DatasetError, load_dataset, read_boxes
from dcfkit.experiments import runs_by_sequence


@pytest.fixture(scope="module")
def evaluated(tmp_path_factory) -> Path:
    """Three synthetic sequences of 24 frames (``data``) and KCF and DSST run on them under TRE
    and SRE by ``dcfkit eval`` (``out/<tracker>/<experiment>/``)."""
    folder = tmp_path_factory.mktemp("compare_tre")
    for i in range(3):
        write_otb(folder / "data", f"seq{i}", seed=i, n_frames=24)
    for experiment in ("tre", "sre"):
        assert cli.main(["eval", "kcf", "dsst", "--dataset", "otb", "--root", str(folder / "data"),
                         "--out", str(folder / "out"), "--experiment", experiment, "--jobs", "1"]) == 0
    return folder


@pytest.mark.parametrize("experiment", ["tre", "sre"])
def test_pooled_scores_are_the_reports_and_iou_and_divergence_run_by_run(evaluated, experiment):
    seqs = load_dataset("otb", evaluated / "data")
    out = evaluated / "out"
    res = compare_folders(out / "kcf" / experiment, out / "dsst" / experiment, seqs, experiment=experiment)
    evaluation, _ = score_and_write(out, seqs, ["kcf", "dsst"], evaluated / f"report_{experiment}",
                                    experiment=experiment)
    reported = {(r["tracker"], r["sequence"]): r for r in evaluation.per_sequence}
    runs = runs_by_sequence(seqs, experiment)
    assert [r["sequence"] for r in res["rows"]] == [s.name for s in seqs] and res["experiment"] == experiment
    for row in res["rows"]:
        name = row["sequence"]
        for score in ("auc", "precision"):
            assert row[score] == reported[("kcf", name)][score]
            assert row[f"{score}_ref"] == reported[("dsst", name)][score]
        pairs = [(read_boxes(out / "kcf" / experiment / f"{run.name}.txt"),
                  read_boxes(out / "dsst" / experiment / f"{run.name}.txt")) for run in runs[name]]
        assert row["frames"] == sum(len(a) for a, _ in pairs) == sum(len(run) for run in runs[name])
        assert row["iou"] == pytest.approx(np.mean(np.concatenate([series_iou(a, b) for a, b in pairs])), abs=1e-12)
        apart = [(k, f) for k, (a, b) in enumerate(pairs, 1) if (f := first_divergence(a, b, 2.0)) is not None]
        assert row["diverges_at"] == (f"{apart[0][0]}:{apart[0][1]}" if apart else None)
    assert res["diverged"] > 0  # KCF and DSST part somewhere


def test_a_sequence_missing_a_run_is_left_out_and_the_cli_reads_the_experiments_folder(evaluated, tmp_path, capsys):
    seqs = load_dataset("otb", evaluated / "data")
    ours = tmp_path / "kcf"
    shutil.copytree(evaluated / "out" / "kcf", ours)
    first = runs_by_sequence(seqs, "tre")["seq1"][4].name
    for suffix in (".txt", ".json", ".time", ".confidence"):
        (ours / "tre" / f"{first}{suffix}").unlink(missing_ok=True)
    res = compare_folders(ours / "tre", evaluated / "out" / "dsst" / "tre", seqs, experiment="tre")
    assert [r["sequence"] for r in res["rows"]] == ["seq0", "seq2"]
    assert res["left_out"]["only_in_reference"] == ["seq1"] and res["left_out"]["incomplete"] == []
    theirs = tmp_path / "dsst"  # another run of seq1 missing on the other side: complete in neither
    shutil.copytree(evaluated / "out" / "dsst", theirs)
    (theirs / "tre" / f"{runs_by_sequence(seqs, 'tre')['seq1'][7].name}.txt").unlink()
    res = compare_folders(ours / "tre", theirs / "tre", seqs, experiment="tre")
    assert [r["sequence"] for r in res["rows"]] == ["seq0", "seq2"]
    assert res["left_out"]["only_in_reference"] == [] and res["left_out"]["incomplete"] == ["seq1"]
    # the tracker folder is given: its tre/ is read, and the table says which experiment
    assert cli.main(["compare", str(ours), str(evaluated / "out" / "dsst"), "--dataset", "otb",
                     "--root", str(evaluated / "data"), "--experiment", "tre", "--format", "json"]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert printed["results"] == str(ours / "tre") and printed["experiment"] == "tre"
    assert [r["sequence"] for r in printed["rows"]] == ["seq0", "seq2"]
    assert cli.main(["compare", str(ours), str(evaluated / "out" / "dsst"), "--dataset", "otb",
                     "--root", str(evaluated / "data"), "--experiment", "tre"]) == 0
    assert capsys.readouterr().out.startswith("experiment TRE (")


def test_one_pass_folders_compare_no_runs_and_reset_is_refused(evaluated):
    seqs = load_dataset("otb", evaluated / "data")
    with pytest.raises(DatasetError, match="no sequence has all its TRE runs in both"):
        compare_folders(evaluated / "out" / "kcf" / "sre", evaluated / "out" / "dsst" / "sre", seqs,
                        experiment="tre")
    with pytest.raises(DatasetError, match="reset runs are scored by dcfkit report --experiment reset"):
        compare_folders(evaluated / "out" / "kcf" / "tre", evaluated / "out" / "dsst" / "tre", seqs,
                        experiment="reset")
