"""csr_reliability on hand-made responses; regional maxima against a brute-force search."""
import numpy as np
import pytest

import dcfkit
from dcfkit.components.channel_weights import CSRReliability, detection_reliability, maxima_values
from dcfkit.datasets.synthetic import make_sequence


def bumps(shape, peaks):
    """A map of Gaussian bumps: ((y, x), height) each, σ 1.5, on 0."""
    yy, xx = np.mgrid[0:shape[0], 0:shape[1]]
    return sum(h * np.exp(-((yy - y) ** 2 + (xx - x) ** 2) / (2 * 1.5**2)) for (y, x), h in peaks).astype(np.float32)


def brute_regional_maxima(r):
    """Flood-fill every flat zone; keep those whose every outer neighbour is lower (imregionalmax)."""
    H, W = r.shape
    seen = np.zeros(r.shape, bool)
    values = []
    for i in range(H):
        for j in range(W):
            if seen[i, j]:
                continue
            zone, stack, is_max = [], [(i, j)], True
            seen[i, j] = True
            while stack:
                a, b = stack.pop()
                zone.append((a, b))
                for da in (-1, 0, 1):
                    for db in (-1, 0, 1):
                        u, v = a + da, b + db
                        if 0 <= u < H and 0 <= v < W and (u, v) != (a, b):
                            if r[u, v] > r[a, b]:
                                is_max = False
                            elif r[u, v] == r[a, b] and not seen[u, v]:
                                seen[u, v] = True
                                stack.append((u, v))
            if is_max:
                values.append(r[i, j])
    return sorted(values, reverse=True)


@pytest.mark.parametrize("seed", range(5))
def test_maxima_values_match_a_flood_fill(seed):
    rng = np.random.default_rng(seed)
    r = rng.integers(0, 4, (9, 11)).astype(np.float32)  # few levels: plateaus, and plateaus next to higher ones
    stack = np.stack([r, r[::-1], np.zeros_like(r)])
    got = maxima_values(stack)
    for c in range(3):
        np.testing.assert_array_equal(got[c], brute_regional_maxima(stack[c]))


def test_detection_reliability_by_hand():
    one = bumps((30, 30), [((15, 15), 1.0)])
    two = bumps((30, 30), [((8, 8), 1.0), ((22, 22), 0.6)])  # second peak 0.6 of the first (the map's min ~0)
    weak = bumps((30, 30), [((8, 8), 1.0), ((22, 22), 0.2)])
    flat = np.full((30, 30), 3.0, np.float32)
    got = detection_reliability(np.stack([one, two, weak, flat]))
    low = float(two.min())  # normalised to [0, 1] first
    assert got[0] == 1.0 and got[3] == 1.0
    assert got[1] == 0.5  # 1 - 0.6 = 0.4, raised to the floor
    assert got[2] == pytest.approx(1 - (0.2 - low) / (1 - low), abs=1e-6)


def test_weights_learn_from_the_maxima_and_detection_and_weight_the_responses():
    w = CSRReliability(CSRReliability.Params(learning_rate=0.5))
    w.reset()
    maps = np.stack([bumps((20, 20), [((5, 5), h)]) for h in (1.0, 3.0)])
    w.learn(maps)  # frame 1: the maxima 1 and 3, normalised
    np.testing.assert_allclose(w.weights, [0.25, 0.75])
    combined = w.combine(maps[None])
    np.testing.assert_allclose(combined[0], 0.25 * maps[0] + 0.75 * maps[1], rtol=1e-6)
    # a detection where channel 1 had a second peak at 0.7 of its first: reliability 0.5 (floor)
    w.observe(np.stack([bumps((20, 20), [((5, 5), 1.0)]), bumps((20, 20), [((5, 5), 1.0), ((15, 15), 0.7)])]))
    np.testing.assert_allclose(w.discrimination, [1.0, 0.5], atol=1e-3)
    w.learn(maps)  # new: 1 * 1 and 3 * 0.5, normalised to 0.4, 0.6; averaged with 0.25, 0.75 at rate 0.5
    np.testing.assert_allclose(w.weights, [0.325, 0.675], atol=1e-3)


def test_one_channel_is_weighed_as_beside_others():
    """A tracker with one feature channel (gray) gives (1, H, W) maps, square or not: each is
    weighed as it is in a stack of two."""
    for shape in ((20, 20), (20, 30)):
        two = bumps(shape, [((5, 5), 1.0), ((15, 15), 0.7)])
        alone = detection_reliability(two[None])
        np.testing.assert_array_equal(alone, detection_reliability(np.stack([two, two]))[:1])
        assert alone[0] == pytest.approx(0.5)  # 1 - 0.7 = 0.3, raised to the floor


def test_csr_dcf_tracks_with_gray_features_alone():
    """CSR-DCF with the gray feature alone and a non-square search area: its one channel's
    reliability each frame (OpenCV's dilation of one channel once broke its shape)."""
    seq = make_sequence(n_frames=4, size=(120, 160), target=(14, 26))
    tracker = dcfkit.load_tracker("csrdcf", overrides={"tracker.search_area_shape": "proportional",
                                                       "tracker.sampling": "subpixel", "tracker.resize": "auto",
                                                       "features": [{"name": "gray"}]})
    tracker.init(seq.frames[0], seq.ground_truth[0])
    for frame in seq.frames[1:]:
        tracker.update(frame)
    assert tracker.channel_weights.discrimination.shape == (1,)
