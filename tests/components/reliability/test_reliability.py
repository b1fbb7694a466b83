"""Reliability scores on hand-made response maps: MOSSE's PSR and LMCF's history test."""
import numpy as np
import pytest

from dcfkit.components.labels.base import Detection
from dcfkit.components.reliability import LMCF, PSR, peak_to_sidelobe
from dcfkit.errors import ConfigError
from dcfkit.registry import get_registry


def detection(response, peak=None):
    r = np.asarray(response, dtype=np.float32)
    peak = peak or tuple(int(i) for i in np.unravel_index(np.argmax(r), r.shape))
    return Detection(r, peak, (2.0, 2.0))


def test_psr_of_a_map_by_hand():
    r = np.zeros((5, 5))
    r[0, 0] = 10.0  # the peak, at the circular origin
    r[2, 2], r[2, 3] = 2.0, -2.0  # outside the 3 x 3 window (exclude 1), which wraps to rows/cols 4, 0, 1
    # the sidelobe: 25 - 9 = 16 cells, values 2, -2 and 14 zeros: mean 0, std sqrt(8 / 16)
    assert peak_to_sidelobe(r, (0, 0), exclude=1) == pytest.approx(10.0 / np.sqrt(0.5))
    assert PSR(PSR.Params(threshold=2.0, exclude=1)).score(detection(r)) == pytest.approx(10.0 / np.sqrt(0.5) / 2)


def test_psr_is_zero_for_a_flat_sidelobe_or_none():
    r = np.ones((4, 4))
    r[1, 1] = 3.0
    assert peak_to_sidelobe(r, (1, 1), exclude=0) == 0.0  # the sidelobe has no spread
    assert peak_to_sidelobe(r, (1, 1), exclude=2) == 0.0  # the window covers the whole map


def peaked(height, floor=0.0):
    """A 4 x 4 map: one cell at ``height``, the rest at ``floor``. APCE = (h - f)² / ((h - f)² / 16) = 16."""
    r = np.full((4, 4), floor)
    r[0, 0] = height
    return detection(r)


def test_lmcf_scores_against_the_average_of_earlier_frames_by_hand():
    lmcf = LMCF(LMCF.Params(peak_ratio=0.5, apce_ratio=0.5))
    first = peaked(2.0)
    assert lmcf.score(first) == pytest.approx(2.0)  # no history: its own average, 1 / 0.5
    lmcf.observe(first, 2.0)
    lmcf.observe(peaked(4.0), lmcf.score(peaked(4.0)))  # peak 4 / (0.5 * 2) = 4, APCE 16 / (0.5 * 16) = 2
    # history: peaks 2 and 4 (mean 3), APCE 16 twice; a peak of 1.2 gives 1.2 / 1.5 = 0.8
    assert lmcf.score(peaked(1.2)) == pytest.approx(0.8)
    flat = np.zeros((4, 4))
    flat[0, 0], flat[2, 2] = 3.0, 3.0  # two peaks: APCE 9 / (18 / 16) = 8, 8 / (0.5 * 16) = 1; peak 3 / 1.5 = 2
    assert lmcf.score(detection(flat)) == pytest.approx(1.0)


def test_a_lasting_drop_lowers_the_bar_until_the_frames_pass_again():
    lmcf = LMCF(LMCF.Params(peak_ratio=0.5, apce_ratio=0.0))
    for _ in range(4):
        lmcf.observe(peaked(4.0), 2.0)
    scores = []
    for _ in range(9):  # a lasting drop to a peak of 1: the bar, half the mean, falls towards 0.5
        scores.append(lmcf.score(peaked(1.0)))
        lmcf.observe(peaked(1.0), scores[-1])
    # the mean before the k-th low frame is (16 + k) / (4 + k); score = 1 / (0.5 mean)
    assert scores == pytest.approx([2 * (4 + k) / (16 + k) for k in range(9)])
    assert max(scores[:8]) < 1 and scores[8] == pytest.approx(1.0)  # the ninth passes: 24 / 12 = 2


def test_lmcf_with_one_measure_off_and_both_off():
    peak_only = LMCF(LMCF.Params(peak_ratio=1.0, apce_ratio=0.0))
    peak_only.observe(peaked(2.0), 1.0)
    two = np.zeros((4, 4))
    two[0, 0] = two[2, 2] = 3.0  # a low APCE, but only the peak is tested: 3 / 2
    assert peak_only.score(detection(two)) == pytest.approx(1.5)
    with pytest.raises(ConfigError, match="both 0"):
        LMCF(LMCF.Params(peak_ratio=0.0, apce_ratio=0.0))


def test_lmcf_reset_forgets_the_history():
    lmcf = LMCF()
    lmcf.observe(peaked(10.0), 5.0)
    lmcf.reset()
    assert lmcf.score(peaked(1.0)) == pytest.approx(min(1 / 0.7, 1 / 0.45))


def test_reliability_components_are_registered_and_checked():
    registry = get_registry()
    assert {"lmcf", "psr"} <= set(registry.names("reliability"))
    with pytest.raises(ConfigError, match="peak_ratio"):
        registry.build("reliability", {"name": "lmcf", "peak_ratio": -1}, "test")
