"""Local maxima of circular maps against brute force; regional maxima (MATLAB's imregionalmax)
against a flood fill of every plateau."""
import collections
import itertools

import numpy as np
import pytest

from dcfkit.numerics.maxima import components, local_maxima, maxima_components, regional_maxima


@pytest.mark.parametrize("size, dtype", [(3, np.float32), (3, np.float64), (5, np.float32), (7, np.float64)])
def test_local_maxima_match_brute_force(size, dtype):
    rng = np.random.default_rng(1)
    r = rng.standard_normal((9, 11)).astype(dtype)
    rows, cols = local_maxima(r, size)
    H, W = r.shape
    brute = []
    offsets = range(-(size // 2), size // 2 + 1)
    for y, x in itertools.product(range(H), range(W)):
        neigh = [r[(y + dy) % H, (x + dx) % W] for dy in offsets for dx in offsets if dy or dx]
        if r[y, x] >= max(neigh):
            brute.append((y, x))
    assert sorted(zip(rows.tolist(), cols.tolist())) == sorted(brute)
    values = r[rows, cols]
    assert np.all(np.diff(values) <= 0)  # highest first


def test_flat_map_has_no_local_maxima():
    rows, _ = local_maxima(np.ones((5, 5), np.float32))
    assert rows.size == 0


def imregionalmax_brute(r):
    """MATLAB's imregionalmax (8-connected, default conn for 2-D): every connected plateau of equal
    values whose neighbours outside it (inside the image; not circular) are all strictly lower."""
    h, w = r.shape
    out = np.zeros((h, w), bool)
    seen = np.zeros((h, w), bool)
    for start in itertools.product(range(h), range(w)):
        if seen[start]:
            continue
        plateau, queue, seen[start] = [], collections.deque([start]), True
        is_max = True
        while queue:
            p = queue.popleft()
            plateau.append(p)
            for dy, dx in itertools.product((-1, 0, 1), repeat=2):
                q = (p[0] + dy, p[1] + dx)
                if (dy, dx) == (0, 0) or not (0 <= q[0] < h and 0 <= q[1] < w):
                    continue
                if r[q] == r[start]:
                    if not seen[q]:
                        seen[q] = True
                        queue.append(q)
                elif r[q] > r[start]:
                    is_max = False
        for p in plateau:
            out[p] = is_max
    return out


@pytest.mark.parametrize("seed, shape, levels", [(0, (9, 11), 3), (1, (12, 12), 4), (2, (7, 16), 2),
                                                 (3, (10, 10), 6), (4, (13, 9), 3), (5, (6, 6), 1000)])
def test_regional_maxima_match_imregionalmax(seed, shape, levels):
    rng = np.random.default_rng(seed)
    r = (rng.integers(0, levels, shape) / levels).astype(np.float32)  # quantised: many plateaus
    expected = imregionalmax_brute(r)
    assert np.array_equal(regional_maxima(r), expected)


def test_regional_maxima_of_special_maps():
    flat = np.full((4, 5), 0.3, np.float32)
    assert regional_maxima(flat).all()  # one plateau with no outer neighbour: a maximum
    r = np.zeros((6, 6), np.float32)
    r[0:3, 0:3] = 1.0
    r[2, 2] = 2.0  # the plateau has a higher pixel inside its own neighbourhood: not a maximum
    expected = np.zeros((6, 6), bool)
    expected[2, 2] = True
    assert np.array_equal(regional_maxima(r), expected)
    r = np.zeros((5, 5), np.float32)
    r[0, 0] = r[0, 1] = r[1, 2] = 1.0  # a diagonal step joins (1, 2) to the plateau: 8-connected
    r[4, 4] = 0.5
    expected = (r > 0)
    assert np.array_equal(regional_maxima(r), expected)
    # a diagonal chain (1, 1), (2, 2), (3, 3) is one plateau; (3, 3) touches the higher (4, 4), so none
    # of it is a maximum, although (1, 1) only touches the plateau's (2, 2)
    r = np.zeros((6, 6), np.float32)
    r[1, 1] = r[2, 2] = r[3, 3] = 1.0
    r[4, 4] = 2.0
    expected = np.zeros((6, 6), bool)
    expected[4, 4] = True
    assert np.array_equal(regional_maxima(r), expected)


def test_a_stack_has_each_planes_own_maxima():
    """Planes are never joined: a plateau in one plane beside a higher pixel of the next is a maximum."""
    rng = np.random.default_rng(6)
    stack = (rng.integers(0, 3, (4, 9, 10)) / 3).astype(np.float32)
    stack[1] = stack[0]  # equal neighbouring planes: a 3-D labelling would join their plateaus
    stack[2, :, :] = 0.5
    got = regional_maxima(stack)
    assert got.shape == stack.shape
    for plane, expected in zip(got, stack):
        assert np.array_equal(plane, imregionalmax_brute(expected))


@pytest.mark.parametrize("dtype", [np.float64, np.int32, np.uint8])
def test_other_dtypes_keep_their_values(dtype):
    """float64 values closer than float32 resolves are told apart; integer maps are read exactly."""
    r = np.zeros((5, 7), dtype)
    r[1, 1], r[3, 5] = 3, 2
    if dtype == np.float64:
        r[1, 2] = 3 + 1e-12  # float32 would make (1, 1) and (1, 2) one plateau
    assert np.array_equal(regional_maxima(r), imregionalmax_brute(r))


def test_components_are_eight_connected_and_planewise():
    mask = np.zeros((5, 5), bool)
    mask[0, 0] = mask[1, 1] = mask[3, 3] = True
    labels, n = components(mask)
    assert n == 2 and labels[0, 0] == labels[1, 1] != labels[3, 3]
    stacked, n = components(np.stack([mask, mask], axis=-1))
    assert n == 4 and stacked[0, 0, 0] != stacked[0, 0, 1]


@pytest.mark.parametrize("seed", range(4))
def test_maxima_components_number_the_regional_maxima_plateaus(seed):
    """Quantised maps, where many plateaus touch a higher pixel and are dropped: the labels
    cover exactly the regional maxima, numbered 1 to count without gaps, one label a plateau
    (one value, connected, never across maps)."""
    rng = np.random.default_rng(seed)
    stack = (rng.integers(0, 4, (3, 11, 13)) / 4).astype(np.float32)
    labels, count = maxima_components(stack)
    assert np.array_equal(labels > 0, regional_maxima(stack))
    assert sorted(np.unique(labels[labels > 0])) == list(range(1, count + 1))
    assert count == sum(components(plane)[1] for plane in regional_maxima(stack))
    for label in range(1, count + 1):
        plane, rows, cols = np.nonzero(labels == label)
        assert len(set(plane)) == 1 and len(set(stack[plane, rows, cols])) == 1
    single, n = maxima_components(stack[0])
    assert single.shape == stack[0].shape and n == components(regional_maxima(stack[0]))[1]


@pytest.mark.parametrize("shape", [(5, 5), (5, 4), (1, 7)])
def test_a_stack_of_one_map_is_that_map(shape):
    """OpenCV returns the dilation of one channel without its channel axis: a (1, H, W) stack
    has the maxima of its one map, square or not, as it has beside another map."""
    rng = np.random.default_rng(sum(shape))
    r = (rng.integers(0, 3, shape) / 3).astype(np.float32)
    expected = imregionalmax_brute(r)
    assert np.array_equal(regional_maxima(r[None]), expected[None])
    assert np.array_equal(regional_maxima(np.stack([r, np.zeros_like(r)]))[0], expected)
    labels, count = maxima_components(r[None])
    assert labels.shape == (1, *shape) and count == components(expected)[1]
