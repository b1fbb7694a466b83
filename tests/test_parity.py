"""The reference presets against the authors' own boxes (skipped without ../shared/data).

Each preset in ``configs/reference/`` is run through ``dcfkit eval``'s runner and set beside
boxes of the authors' code with ``dcfkit compare``'s library function. Issue 13's bar: on
every sequence |ΔAUC| <= 0.02 and a mean IoU between the two box series >= 0.8. The
authors' boxes come from:

* DR²Track: ``tests/data/authors_octave/DR2Track`` (``run_DR2Track.m`` under GNU Octave 7.3 by
  ``benchmarks/authors_octave.sh``, 2026-11-25, with the stand-in mexResize that follows the
  compiled mex's 'auto' rule; ``reference_results/DR2Track`` was made with the earlier stand-in,
  which compared with the old width, and parts from it on the DSST's non-square scale samples);
* STRCF: ``tests/data/authors_octave/STRCF`` (``run_STRCF.m`` under GNU Octave 7.3 by
  ``benchmarks/authors_octave.sh``; see that folder's README);
* BACF: ``reference_results/BACF`` (their published MATLAB result files), and for
  wakeboard7 ``tests/data/authors_octave/BACF`` (their code under Octave), because from
  frame 16 of wakeboard7, where two of the five scales score 0.07% apart, the published
  file departs from a run of the authors' own code here (the xfail below).

Measured when written (2026-11-24): STRCF identical box for box on all eight sequences; BACF
identical or IoU >= 0.995 on the five, identical to the Octave run on wakeboard7.

DR²Track against the 2026-11-25 runs: identical box for box (0.01 px) on six of the eight;
building4 and truck4_2 differ on isolated frames from frame 69 and 109, where dcfkit's
displacement before round() lies within 0.003 px of a half pixel (1.4979, -0.4997 px) and the
authors' rounds the other way (|ΔAUC| <= 0.001, IoU >= 0.998, no centre more than 2 px apart).

ARCF-HC and AutoTrack, whose shipped configs are their authors' code, against the authors'
published MATLAB files (issue 16's bar: |ΔAUC| <= 0.03 on each sequence, the mean within 0.02)
and against their code under Octave (``tests/data/authors_octave/{ARCF-HC,AutoTrack}``).
Measured 2026-11-25: ARCF |ΔAUC| <= 0.019 and mean -0.004 against MATLAB, <= 0.007 against
Octave; AutoTrack <= 0.011 on four sequences against MATLAB (<= 0.006 against Octave), and on
truck4_1 and wakeboard10, where its occlusion test is decided by rounding, +0.060 and +0.089
(the xfail; the authors' own code under Octave: -0.006 and +0.040).
"""
from pathlib import Path

import pytest

from dcfkit.compare import compare_folders
from dcfkit.config import load_config
from dcfkit.datasets import load_dataset
from dcfkit.evaluation import run_one_pass

OCTAVE_RUNS = Path(__file__).parent / "data" / "authors_octave"
UAV = ("uav123_10fps", "UAV123_10fps")
FAITHFUL = ("arcf", "autotrack")  # shipped configs that are their authors' code
# AutoTrack's occlusion test divides by its last response map, whose values near zero are
# float32 rounding noise: where a frame's test sits near its threshold, a last-bit change flips
# it (scipy's FFT for pyfftw moves wakeboard10 by 0.030 AUC), and MATLAB, Octave and dcfkit
# each take their own branch on these two (docs/results.md)
AUTOTRACK_ROUNDING_BOUND = ("truck4_1", "wakeboard10")


def compare_preset(preset, dataset, folder, sequences, reference, shared_data, tmp_path):
    """Run ``configs/reference/<preset>.yaml`` (or the shipped config ``preset`` when it names no
    reference preset: ARCF's and AutoTrack's are their authors' code) on the sequences and
    compare it with ``reference``."""
    seqs = load_dataset(dataset, shared_data / folder, sequences)
    config = load_config(preset if preset in FAITHFUL else f"reference/{preset}")
    run_one_pass(config, seqs, tmp_path, progress=False)
    table = compare_folders(tmp_path / config["name"], reference, seqs, protocol="otb")
    assert [r["sequence"] for r in table["rows"]] == [s.name for s in seqs]
    return table["rows"]


def assert_within_the_bar(rows):
    for row in rows:
        assert abs(row["d_auc"]) <= 0.02, row
        assert row["iou"] >= 0.8, row


@pytest.mark.parametrize("dataset,folder,sequences", [UAV + (None,), ("dtb70", "DTB70", ["Gull1"]),
                                                      ("uavdt", "UAVDT", ["S0601"])])
def test_dr2track_reference_is_the_authors_code(dataset, folder, sequences, shared_data, tmp_path):
    reference = OCTAVE_RUNS / "DR2Track" / folder
    rows = compare_preset("dr2track", dataset, folder, sequences, reference, shared_data, tmp_path)
    assert_within_the_bar(rows)
    for row in rows:
        assert row["diverges_at"] is None and row["iou"] >= 0.99, row


@pytest.mark.parametrize("dataset,folder", [UAV, ("dtb70", "DTB70"), ("uavdt", "UAVDT")])
def test_strcf_reference_is_the_authors_code_box_for_box(dataset, folder, shared_data, tmp_path):
    reference = OCTAVE_RUNS / "STRCF" / folder
    rows = compare_preset("strcf", dataset, folder, None, reference, shared_data, tmp_path)
    assert_within_the_bar(rows)
    for row in rows:  # box for box: their boxes are whole pixels (report_tracking_result's round)
        assert row["iou"] == 1.0, row


def test_bacf_reference_reproduces_the_published_boxes(shared_data, tmp_path):
    sequences = ["boat1", "building4", "truck4_1", "truck4_2", "wakeboard10"]
    reference = shared_data / "reference_results" / "BACF" / "UAV123_10fps"
    assert_within_the_bar(compare_preset("bacf", *UAV, sequences, reference, shared_data, tmp_path))


def test_bacf_reference_is_the_authors_code_on_wakeboard7(shared_data, tmp_path):
    reference = OCTAVE_RUNS / "BACF" / "UAV123_10fps"
    (row,) = compare_preset("bacf", *UAV, ["wakeboard7"], reference, shared_data, tmp_path)
    assert row["iou"] == 1.0, row  # box for box (whole pixels: floor(target_sz), pos - floor(sz/2))


@pytest.mark.xfail(strict=True, reason=(
    "the published MATLAB file departs from the authors' own code run here (Octave) at frame 16 of "
    "wakeboard7, where scales 4 and 5 score 0.0089659 and 0.0089725; dcfkit's preset gives the Octave "
    "run's boxes exactly (test above). The platform difference (image decoding or build) is not known."))
def test_bacf_reference_on_wakeboard7_against_the_published_file(shared_data, tmp_path):
    reference = shared_data / "reference_results" / "BACF" / "UAV123_10fps"
    assert_within_the_bar(compare_preset("bacf", *UAV, ["wakeboard7"], reference, shared_data, tmp_path))


def published(tracker, shared_data):
    """The authors' published MATLAB result files of ``tracker`` on UAV123@10fps."""
    return shared_data / "reference_results" / tracker / "UAV123_10fps"


def test_arcf_reproduces_the_authors_published_scores(shared_data, tmp_path):
    """Issue 16's bar against the authors' MATLAB result files: |ΔAUC| <= 0.03 on every sequence,
    the mean within 0.02; and issue 13's against their code run here under Octave."""
    rows = compare_preset("arcf", *UAV, None, published("ARCF-HC", shared_data), shared_data, tmp_path)
    assert all(abs(row["d_auc"]) <= 0.03 for row in rows), rows
    assert abs(sum(row["d_auc"] for row in rows)) / len(rows) <= 0.02
    assert_within_the_bar(compare_preset("arcf", *UAV, None, OCTAVE_RUNS / "ARCF-HC" / "UAV123_10fps", shared_data,
                                         tmp_path / "octave"))


def test_autotrack_reproduces_the_authors_published_scores(shared_data, tmp_path):
    """Issue 16's bar on the four sequences whose occlusion tests rounding does not decide
    (the other two: the xfail below), against the published files and their code under Octave."""
    stable = [s for s in ("boat1", "building4", "truck4_1", "truck4_2", "wakeboard7", "wakeboard10")
              if s not in AUTOTRACK_ROUNDING_BOUND]
    rows = compare_preset("autotrack", *UAV, stable, published("AutoTrack", shared_data), shared_data, tmp_path)
    assert all(abs(row["d_auc"]) <= 0.03 for row in rows), rows
    assert abs(sum(row["d_auc"] for row in rows)) / len(rows) <= 0.02
    assert_within_the_bar(compare_preset("autotrack", *UAV, stable, OCTAVE_RUNS / "AutoTrack" / "UAV123_10fps",
                                         shared_data, tmp_path / "octave"))


@pytest.mark.xfail(strict=True, reason=(
    "AutoTrack's occlusion test (eta = norm(response_diff) / 1e4 >= 0.3, response_diff divided by the last "
    "response map) is decided by float32 rounding where it sits near its threshold: on truck4_1 and "
    "wakeboard10 the published MATLAB file, the authors' code under Octave and dcfkit part there "
    "(truck4_1 AUC 0.535 / 0.529 / 0.595, wakeboard10 0.412 / 0.452 / 0.500)"))
def test_autotrack_on_its_rounding_bound_sequences(shared_data, tmp_path):
    rows = compare_preset("autotrack", *UAV, list(AUTOTRACK_ROUNDING_BOUND), published("AutoTrack", shared_data),
                          shared_data, tmp_path)
    assert all(abs(row["d_auc"]) <= 0.03 for row in rows), rows
