"""The Color Names table and feature."""
import hashlib

import numpy as np
import pytest

from dcfkit.components.features import colornames as cn
from dcfkit.components.features.base import cell_average
from dcfkit.components.features.colornames import ColorNames
from dcfkit.components.features.gray import Gray
from dcfkit.errors import ConfigError

# SHA-256 of the 32768x10 float32 normalised CN table compiled into opencv-contrib-python-headless,
# written here independently of the loader's own constant
PUBLISHED_SHA256 = "e6a0a45f68cf5880d018f9e2f82dff180e992296d335b0fa8eb253b9db403ec0"


def test_table_is_found_and_verified():
    table = cn.load_table()
    assert table.shape == (32768, 10) and table.dtype == np.float32
    assert hashlib.sha256(table.tobytes()).hexdigest() == PUBLISHED_SHA256 == cn.SHA256
    # the published first row of the normalised CN table
    np.testing.assert_allclose(table[0, :4], [0.45975, 0.014802, 0.044289, -0.028193], rtol=1e-6)
    # each row is an 11-name probability vector p projected orthonormally onto the sum-zero
    # subspace: |row|² = |p|² - 1/11, in [0, 10/11], reaching 10/11 for a certain colour name
    norms = np.sum(table.astype(np.float64) ** 2, axis=1)
    assert norms.max() == pytest.approx(10 / 11, abs=1e-5)


def test_table_index_is_r_plus_32g_plus_1024b():
    bgr = np.array([[[0, 0, 255], [0, 255, 0], [255, 0, 0], [17, 130, 9]]], np.uint8)
    assert cn.table_index(bgr).tolist() == [[31, 31 * 32, 31 * 1024, 9 // 8 + 32 * (130 // 8) + 1024 * (17 // 8)]]


@pytest.mark.parametrize("shape", [(8, 12, 3), (10, 15, 3)])  # the second: partial cells dropped
def test_feature_is_the_cell_mean_of_table_rows(shape):
    rng = np.random.default_rng(0)
    patch = rng.integers(0, 256, shape, dtype=np.uint8)
    got = ColorNames().extract(patch, 4)
    table = cn.load_table()
    assert got.shape == (10, 2, 3)
    for cy in range(2):
        for cx in range(3):
            block = patch[4 * cy:4 * cy + 4, 4 * cx:4 * cx + 4]
            np.testing.assert_allclose(got[:, cy, cx], table[cn.table_index(block)].reshape(-1, 10).mean(0), atol=1e-6)


def test_table_from_file_and_bad_files(tmp_path):
    good = tmp_path / "cn.npy"
    np.save(good, cn.load_table())
    assert np.array_equal(cn.load_table(str(good)), cn.load_table())
    bad = tmp_path / "bad.npy"
    np.save(bad, np.zeros((32768, 10), np.float32))
    with pytest.raises(ConfigError, match="failed its checksum"):
        cn.load_table(str(bad))
    np.save(bad, np.zeros((10, 10), np.float32))
    with pytest.raises(ConfigError, match=r"shape \(10, 10\), expected \(32768, 10\)"):
        cn.load_table(str(bad))
    with pytest.raises(ConfigError, match="file not found"):
        cn.load_table(str(tmp_path / "missing.npy"))


def test_gray_feature_is_centred_cell_mean():
    patch = np.full((8, 8, 3), 255, np.uint8)
    patch[:4, :4] = 0
    got = Gray().extract(patch, 4)
    np.testing.assert_allclose(got[0], [[-0.5, 0.5], [0.5, 0.5]], atol=1e-6)
    np.testing.assert_allclose(cell_average(np.arange(16, dtype=np.float32).reshape(4, 4), 2),
                               [[2.5, 4.5], [10.5, 12.5]])
    # rows and columns beyond the last whole cell are left out, as fhog and Color Names do
    np.testing.assert_allclose(cell_average(np.arange(20, dtype=np.float32).reshape(4, 5), 2),
                               [[3.0, 5.0], [13.0, 15.0]])


def test_matlab_bicubic_pooling_resizes_each_pixels_names():
    # get_csr_features: imresize(im2c(single(im), w2c, -2), out_size); im2c looks each pixel up
    from dcfkit.numerics.imresize import imresize  # only this test

    rng = np.random.default_rng(5)
    patch = rng.integers(0, 256, (16, 12, 3), dtype=np.uint8)
    table = cn.load_table("")
    names = np.array([[table[int(p[2]) // 8 + 32 * (int(p[1]) // 8) + 1024 * (int(p[0]) // 8)] for p in row]
                      for row in patch], np.float64)
    out = ColorNames(ColorNames.Params(pooling="matlab_bicubic")).extract(patch, 4)
    np.testing.assert_allclose(out, imresize(names, (4, 3)).transpose(2, 0, 1), atol=1e-6)
