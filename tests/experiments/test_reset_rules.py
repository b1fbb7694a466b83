"""The reset-based experiment's overlap rules against the toolkits' own code: VOT2016's against
the trax library's region overlap (the vot-trax wheel's libtrax.so; a trax library of 2016 when
$DCFKIT_TRAX2016_LIBRARY names one), vot-toolkit 0.9's against its ``vot.region.raster``."""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest
from libtrax import Trax, library_path

from dcfkit.datasets import load_dataset, read_boxes
from dcfkit.errors import DcfkitError
from dcfkit.experiments.raster import NO_BOUNDS, trax2016_overlap
from dcfkit.experiments.vot import RULES, get_rule

SIZE = (40, 30)  # a small image: many boxes cross its edges


def hostile_pairs(n: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """``n`` (box, ground truth) pairs: half-pixel grids, near misses, slivers under 3 px,
    boxes across and outside the image's edges, fractional coordinates."""
    rng = np.random.default_rng(seed)
    a, b = np.empty((n, 4)), np.empty((n, 4))
    for i in range(n):
        kind = i % 4
        if kind == 0:
            a[i], b[i] = rng.integers(-5, 90, 4) / 2, rng.integers(-5, 90, 4) / 2
        elif kind == 1:
            a[i] = rng.uniform(-20, 60, 4)
            b[i] = a[i] + rng.normal(0, 3, 4)
        elif kind == 2:
            a[i] = np.r_[rng.uniform(-5, 45, 2), rng.uniform(0.01, 2.5, 2)]
            b[i] = np.r_[a[i, :2] + rng.uniform(-3, 3, 2), rng.uniform(0.01, 3, 2)]
        else:
            a[i], b[i] = (np.r_[rng.uniform(-50, 90, 2), rng.uniform(0.2, 60, 2)] for _ in range(2))
    a[:, 2:], b[:, 2:] = np.abs(a[:, 2:]) + 0.01, np.abs(b[:, 2:]) + 0.01
    return a, b


def same(found: np.ndarray, expected: np.ndarray) -> np.ndarray:
    """Equal to 1e-6 (the library's float32), NaN for NaN."""
    return (np.abs(found - expected) <= 1e-6) | (np.isnan(found) & np.isnan(expected))


# how VOT2016 asks the library: the trax client's failure test on rectangle regions in [0, W] x [0, H];
# the MATLAB analysis's own polygons, unbounded (accuracy) and in [0, W - 1] x [0, H - 1] (EAO)
WAYS = {"failure": (True, (0, 0, SIZE[0], SIZE[1])), "accuracy": (False, None),
        "eao": (False, (0, 0, SIZE[0] - 1, SIZE[1] - 1))}


def reference(lib: Trax, boxes, gts, inclusive: bool, bounds) -> np.ndarray:
    ask = lib.rectangles if inclusive else lib.polygons
    return np.array([ask(box, gt, bounds) for box, gt in zip(boxes, gts)])


@pytest.fixture(scope="module")
def libtrax() -> Trax:
    path = library_path()
    if path is None:
        pytest.skip("vot-trax (its libtrax.so) is not installed: pip install vot-trax, as the test extras do")
    return Trax(path)


def test_a_hand_computed_case_of_each_rule():
    box, gt = [0, 0, 10, 10], [5, 0, 10, 10]
    vot2016, toolkit = get_rule("vot2016"), get_rule("vot-toolkit")
    assert vot2016.failure(box, gt, (640, 480))[0] == pytest.approx(50 / 150)  # pixels 0..9 and 5..14, 10 rows
    assert vot2016.failure(box, gt, (12, 20))[0] == pytest.approx(50 / 130)  # 5..14 cut to 5..12: [0, W]
    assert vot2016.accuracy(box, gt, (12, 20))[0] == pytest.approx(66 / 176)  # 0..10 and 5..15, 11 rows
    assert vot2016.eao(box, gt, (12, 20))[0] == pytest.approx(66 / 132)  # 0..10 and 5..11 in columns 0..11
    assert toolkit.accuracy(box, gt, (12, 20))[0] == pytest.approx(50 / 120)  # 0..9 and 5..11, 10 rows


def test_a_one_pixel_sliver_is_a_failure_where_a_continuous_overlap_kept_it():
    """A box 1 px wide over the ground truth's last 0.4 px: a continuous overlap of 4 / 106
    (dcfkit <= 0.9.0) kept the tracker; both toolkits round it off the ground truth."""
    box, gt = [9.6, 0, 1, 10], [0, 0, 10, 10]
    for rule in RULES.values():
        assert rule.failed(box, gt, (640, 480)), rule.name


def test_missing_boxes_fail_and_missing_ground_truth_never_does():
    for rule in RULES.values():
        assert rule.failed([np.nan] * 4, [0, 0, 5, 5], (40, 30)) and rule.failed([0, 0, 0, 5], [0, 0, 5, 5], (40, 30))
        assert np.isnan(rule.failure([0, 0, 5, 5], [np.nan] * 4, (40, 30))[0])
        assert not rule.failed([0, 0, 5, 5], [0, 0, 0, 5], (40, 30))
    with pytest.raises(DcfkitError, match="unknown reset-based protocol 'otb'; one of: vot2016, vot-toolkit"):
        get_rule("otb")


@pytest.mark.parametrize("way", WAYS)
def test_vot2016_overlaps_are_libtrax_s(libtrax, way):
    """libtrax 4.0.2's default rasterisation is trax 2016's for rectangles whose rounded corners
    are apart (src/region.c's rasterize_polygon since 2019 also fills a span whose two corners
    round to one pixel, which 2016's left empty): boxes at least 2 px across in the polygon."""
    inclusive, bounds = WAYS[way]
    a, b = hostile_pairs(4000)
    span = (a[:, 2:] - inclusive).min(axis=1) >= 2
    span &= (b[:, 2:] - inclusive).min(axis=1) >= 2
    a, b = a[span], b[span]
    expected = reference(libtrax, a, b, inclusive, bounds)
    found = getattr(get_rule("vot2016"), way)(a, b, SIZE)
    assert same(found, expected).all()
    assert ((found <= 0) == (expected <= 0)).all()
    assert (expected > 0).sum() > 300 and (expected == 0).sum() > 300  # both decisions are tested


def test_vot2016_on_slivers_against_a_trax_library_of_2016():
    """Every hostile pair, slivers included, against a trax library built from 2016's region.c
    (the vot-trax wheel's differs there): set $DCFKIT_TRAX2016_LIBRARY to one to run this."""
    path = os.environ.get("DCFKIT_TRAX2016_LIBRARY")
    if not path:
        pytest.skip("no $DCFKIT_TRAX2016_LIBRARY: a trax library of 2016 (docs/evaluation.md, 'Reset-based "
                    "experiment') is not at hand")
    lib = Trax(Path(path))
    a, b = hostile_pairs(4000)
    for way, (inclusive, bounds) in WAYS.items():
        expected = reference(lib, a, b, inclusive, bounds)
        found = trax2016_overlap(a, b, bounds or NO_BOUNDS, inclusive)
        assert same(found, expected).all(), way
        assert np.isnan(expected).sum() > 10  # two empty rasters: the library's 0 / 0


def test_vot_toolkit_overlaps_are_its_raster_code():
    raster = pytest.importorskip("vot.region.raster", reason="vot-toolkit 0.9 is not importable (it is no test "
                                 "extra: it needs opencv-python; docs/evaluation.md says how to run this test)")
    from vot.region.shapes import Rectangle

    a, b = hostile_pairs(2000)
    for size in (SIZE, (7, 5), (1280, 720)):
        expected = np.array([raster.calculate_overlap(Rectangle(*p), Rectangle(*q), size) for p, q in zip(a, b)])
        found = get_rule("vot-toolkit").failure(a, b, size)
        np.testing.assert_allclose(found, expected, rtol=0, atol=1e-12)


def published_pairs(root: Path) -> list[tuple[np.ndarray, np.ndarray, tuple[int, int]]]:
    """(published boxes, ground truth, image size) of every published tracker on the development
    sequences."""
    found = []
    for folder in ("UAV123_10fps", "DTB70", "UAVDT"):
        for seq in load_dataset("auto", root / folder):
            height, width = seq.frame(0).shape[:2]
            for boxes in sorted((root / "published_results").glob(f"*/{folder}/{seq.name}.txt")):
                found.append((read_boxes(boxes), seq.ground_truth, (width, height)))
    return found


def test_vot2016_on_the_published_boxes_of_the_development_sequences(libtrax, shared_data):
    """Every frame of every published tracker on the 8 development sequences: the failure
    overlaps equal libtrax's, and so every failure decision (none of these boxes is a sliver
    whose corners round together, where libtrax 4.0.2 and trax 2016 part: asserted); the
    accuracy's and the EAO's on every fourth tracker-sequence, to keep the CPU time short."""
    pairs = published_pairs(shared_data)
    assert len(pairs) > 150
    rule = get_rule("vot2016")
    failures = 0
    for k, (boxes, gts, (width, height)) in enumerate(pairs):
        keep = np.isfinite(gts).all(axis=1)
        boxes, gts = boxes[keep], gts[keep]
        assert (boxes[:, 2:] >= 3).all() and (gts[:, 2:] >= 3).all()
        expected = reference(libtrax, boxes, gts, True, (0, 0, width, height))
        assert same(rule.failure(boxes, gts, (width, height)), expected).all()
        failures += int((expected <= 0).sum())
        for way, bounds in (("accuracy", None), ("eao", (0, 0, width - 1, height - 1))) if k % 4 == 0 else ():
            assert same(getattr(rule, way)(boxes, gts, (width, height)),
                        reference(libtrax, boxes, gts, False, bounds)).all(), way
    assert failures > 1000  # the published trackers lose the target: both decisions are checked
