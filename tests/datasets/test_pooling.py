"""Pooling several benchmark roots into one set of sequences (``--root A --root B``): one table,
one n, statistics over all; clear errors where the roots cannot be pooled."""
from __future__ import annotations

import json
import shutil
import warnings

import numpy as np
import pytest
from test_datasets import dtb_root, uav_root
from test_layouts import jpg, lasot_root  # noqa: F401  (jpg: a fixture lasot_root needs)

from dcfkit import cli
from dcfkit.analysis.scoring import evaluate
from dcfkit.analysis.statistics import mean_interval
from dcfkit.datasets import DatasetError, DatasetWarning, load_dataset, load_datasets


@pytest.fixture
def roots(tmp_path):
    """A UAV123@10fps root (uav2: 45 frames, uav6: 37; loaded sorted) and a DTB70 root (Car2: 3, Gull1: 5)."""
    return uav_root(tmp_path / "a", seqs=("uav6", "uav2")), dtb_root(tmp_path / "b")[0]


def write_results(folder, sequences, shift: float) -> None:
    """``folder/<sequence>.txt``: the ground truth (1-based) moved right by ``shift`` px per
    sequence index, so every sequence scores differently."""
    folder.mkdir(parents=True, exist_ok=True)
    for i, seq in enumerate(sequences):
        boxes = seq.ground_truth + [1 + shift * (i + 1), 1, 0, 0]
        np.savetxt(folder / f"{seq.name}.txt", boxes, fmt="%.3f", delimiter=",")


def test_two_layouts_pool_into_one_set_scored_and_tested_over_all(roots):
    uav, dtb = roots
    pooled = load_datasets(None, [uav, dtb])  # each root's layout detected
    alone = load_dataset("uav123_10fps", uav) + load_dataset("dtb70", dtb)
    assert [(s.name, s.dataset) for s in pooled] == [(s.name, s.dataset) for s in alone]
    assert [s.dataset for s in pooled] == ["uav123_10fps"] * 2 + ["dtb70"] * 2
    results = {"exact": {s.name: s.ground_truth for s in pooled},
               "off": {s.name: s.ground_truth + [3.0 * (i + 1), 0, 0, 0] for i, s in enumerate(pooled)}}
    scores = evaluate(results, pooled)
    assert {r["sequences"] for r in scores.overall} == {4}
    assert scores.settings["datasets"] == {"uav123_10fps": 2, "dtb70": 2}
    assert scores.statistics.sequences == 4
    # each sequence scores as it does in its own dataset's evaluation; the mean and test run over all four
    apart = [row for part in (alone[:2], alone[2:]) for row in
             evaluate({t: {s.name: r[s.name] for s in part} for t, r in results.items()}, part).per_sequence]
    key = lambda r: (r["tracker"], r["sequence"])  # noqa: E731
    assert sorted(scores.per_sequence, key=key) == sorted(apart, key=key)
    off = [r["auc"] for r in apart if r["tracker"] == "off"]
    exact = [r["auc"] for r in apart if r["tracker"] == "exact"]
    assert scores.statistics.means["off"]["auc"] == mean_interval(off)
    difference = scores.statistics.differences["off"]["auc"]
    assert difference.mean == pytest.approx(np.mean(np.subtract(off, exact)))


def test_compare_on_pooled_roots_reads_every_root(roots, tmp_path, capsys):
    uav, dtb = roots
    sequences = load_datasets(None, [uav, dtb])
    write_results(tmp_path / "A", sequences, 1.0)
    write_results(tmp_path / "B", sequences, 4.0)
    assert cli.main(["compare", str(tmp_path / "A"), str(tmp_path / "B"), "--dataset", "uav123_10fps",
                     "--dataset", "dtb70", "--root", str(uav), "--root", str(dtb), "--format", "json"]) == 0
    res = json.loads(capsys.readouterr().out)
    assert [r["sequence"] for r in res["rows"]] == ["uav2", "uav6", "Car2", "Gull1"]  # root by root
    assert res["statistics"]["auc"]["difference"]["n"] == 4


def test_sequences_select_across_the_roots_and_an_unknown_one_names_them(roots):
    uav, dtb = roots
    assert [s.name for s in load_datasets("auto", [uav, dtb], "Gull1,uav2")] == ["Gull1", "uav2"]
    with pytest.raises(DatasetError, match=r"sequence 'Gull2' not found in the roots .*UAV123_10fps "
                                           r"\(auto\), .*DTB70 \(auto\)\. Did you mean 'Gull1'\?"):
        load_datasets(None, [uav, dtb], ["Gull2"])


def test_a_name_under_two_roots_is_an_error_naming_both(roots, tmp_path):
    _, dtb = roots
    other = shutil.copytree(dtb, tmp_path / "c" / "DTB70")
    with pytest.raises(DatasetError, match=rf"sequence 'Car2' is under two roots, {dtb} \(dtb70\) and "
                                           rf"{other} \(dtb70\): results are named after the sequence"):
        load_datasets("dtb70", [dtb, other])


def test_the_same_root_twice_counts_once_with_a_warning(roots):
    uav, _ = roots
    with pytest.warns(DatasetWarning, match=r"--root .*UAV123_10fps given more than once: its sequences count once"):
        twice = load_datasets(None, [uav, uav / ".." / "UAV123_10fps"])
    assert [s.name for s in twice] == ["uav2", "uav6"]


def test_dataset_names_must_be_one_for_all_or_one_per_root(roots, tmp_path, capsys):
    uav, dtb = roots
    assert len(load_datasets(["uav123_10fps", "dtb70"], [uav, dtb])) == 4  # paired in order
    with pytest.raises(DatasetError, match="2 --dataset for 3 --root: give one --dataset for every root, or one "
                                           "per --root in the same order"):
        load_datasets(["uav123_10fps", "dtb70"], [uav, dtb, tmp_path])
    with pytest.raises(DatasetError, match="no dtb70 sequences under"):  # one name for all: UAV123 is no DTB70
        load_datasets("dtb70", [dtb, uav])
    assert cli.main(["report", str(tmp_path / "none"), "--dataset", "uav123_10fps", "--dataset", "dtb70",
                     "--dataset", "uavdt", "--root", str(uav), "--root", str(dtb)]) != 0
    assert "3 --dataset for 2 --root" in capsys.readouterr().err


def test_benchmarks_scored_by_different_rules_need_a_protocol(tmp_path, jpg, capsys):  # noqa: F811
    lasot, dtb = lasot_root(tmp_path, jpg), dtb_root(tmp_path)[0]
    out = tmp_path / "out"
    assert cli.main(["eval", "kcf", "--root", str(lasot), "--root", str(dtb), "--out", str(out), "--no-progress"]) != 0
    assert "name the protocol that scores them all (--protocol" in capsys.readouterr().err
    assert not out.exists()  # refused before anything ran
    pooled = load_datasets(None, [lasot, dtb])
    results = {"t": {s.name: s.ground_truth for s in pooled}}
    with pytest.raises(DatasetError, match=r"scored by different rules \(lasot: lasot; dtb70: otb\): name the "
                                           r"protocol"):
        evaluate(results, pooled)
    assert evaluate(results, pooled, protocol="otb").overall[0]["sequences"] == len(pooled)


def test_a_single_root_loads_as_before(roots):
    uav, _ = roots
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        one = load_datasets(None, uav, "uav2")
    assert [(s.name, s.annotation) for s in one] == [(s.name, s.annotation) for s in load_dataset(None, uav, "uav2")]


# --------------------------------------------------------------------------- the development set


DEVELOPMENT = ("UAV123_10fps", "DTB70", "UAVDT")


@pytest.mark.realdata
def test_one_report_pools_the_three_development_roots(shared_data, tmp_path, capsys):
    """The eight development sequences of three layouts in one report, scored from the published
    result files (``published_results/<TRACKER>/<DATASET>/<sequence>.txt``)."""
    out = tmp_path / "out"
    names = {}
    for tracker in ("BACF", "STRCF"):
        (out / tracker).mkdir(parents=True)
        for folder in DEVELOPMENT:
            for seq in load_dataset("auto", shared_data / folder):
                names[seq.name] = folder
                (out / tracker / f"{seq.name}.txt").symlink_to(
                    shared_data / "published_results" / tracker / folder / f"{seq.name}.txt")
    roots = [arg for folder in DEVELOPMENT for arg in ("--root", str(shared_data / folder))]
    assert cli.main(["report", str(out), *roots, "--format", "csv"]) == 0
    report = json.loads((tmp_path / "out_report" / "report.json").read_text())
    assert len(names) == 8 and report["statistics"]["sequences"] == 8
    assert report["settings"]["datasets"] == {"uav123_10fps": 6, "dtb70": 1, "uavdt": 1}
    assert {r["tracker"]: r["sequences"] for r in report["overall"]} == {"BACF": 8, "STRCF": 8}
    assert {r["sequence"] for r in report["per_sequence"]} == set(names)
    for tracker in ("BACF", "STRCF"):  # the pooled mean is the mean of the eight sequences' own scores
        auc = [r["auc"] for r in report["per_sequence"] if r["tracker"] == tracker]
        assert report["statistics"]["means"][tracker]["auc"]["mean"] == pytest.approx(np.mean(auc))
