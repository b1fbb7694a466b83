"""The gray-level lookup table feature (ECO's intensity channels) against a per-pixel loop."""
import numpy as np
import pytest

from dcfkit.components.features import IntensityTable
from dcfkit.errors import ConfigError


def test_a_table_is_looked_up_per_pixel_and_averaged_per_cell(tmp_path):
    table = np.random.default_rng(0).standard_normal((256, 5)).astype(np.float32)
    np.save(tmp_path / "t.npy", table)
    feature = IntensityTable(IntensityTable.Params(table_path=str(tmp_path / "t.npy")))
    gray = np.random.default_rng(1).integers(0, 256, (8, 12), np.uint8)
    patch = np.repeat(gray[..., None], 3, axis=2)
    out = feature.extract(patch, 4)
    assert feature.channels() == 5 and out.shape == (5, 2, 3)
    for c in range(5):
        for i in range(2):
            for j in range(3):
                want = np.mean([table[gray[y, x], c] for y in range(4 * i, 4 * i + 4) for x in range(4 * j, 4 * j + 4)])
                assert out[c, i, j] == pytest.approx(want, abs=1e-5)


def test_without_a_table_it_is_the_gray_level_and_a_bad_table_is_named(tmp_path):
    feature = IntensityTable()
    assert feature.channels() == 1
    assert feature.extract(np.full((4, 4, 3), 255, np.uint8), 2) == pytest.approx(0.5)
    np.save(tmp_path / "bad.npy", np.zeros((10, 3), np.float32))
    with pytest.raises(ConfigError, match="no array of 256 rows"):
        IntensityTable(IntensityTable.Params(table_path=str(tmp_path / "bad.npy"))).channels()
