"""The MATLAB stand-ins benchmarks/authors_octave.sh gives the authors' code under GNU Octave
(benchmarks/octave/shims): they must compute what MATLAB's functions compute, or the authors'
boxes made with them are not the authors'."""
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

SHIMS = Path(__file__).resolve().parents[2] / "benchmarks" / "octave" / "shims"

pytestmark = pytest.mark.skipif(shutil.which("octave") is None, reason="GNU Octave is not installed")


def octave(code: str) -> np.ndarray:
    """The numbers ``code`` prints with p() (every digit), run with the shims first on the path and the
    image package loaded (as authors_run.m runs CSR-DCF), as one flat array."""
    has_image = subprocess.run(["octave", "--no-gui", "-q", "--eval", "pkg load image"],
                               capture_output=True, text=True).returncode == 0
    prefix = ("pkg load image; " if has_image else "") + f"warning('off', 'all'); addpath('{SHIMS}'); p = @(v) printf('%.17g\\n', v); "
    done = subprocess.run(["octave", "--no-gui", "-q", "--eval", prefix + code], capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stderr[-2000:]
    return np.array(done.stdout.split(), dtype=float)


def test_imresize_is_matlabs_algorithm():
    """Normalised weights keep a constant image constant when shrinking with antialiasing (Octave's
    own imresize is off by 6e-4 here); mirrored borders and the cubic kernel (a = -0.5) give the
    values worked by hand from MATLAB's contributions(): 1:4 doubled starts at
    -0.0234375*2 + (0.2265625 + 0.8671875)*1 - 0.0703125*2 = 0.90625; 'nearest' at 1/6 takes
    the samples 4, 10, ... (u = 6x - 2.5, box kernel [-0.5, 0.5))."""
    out = octave("a = imresize(0.7 * ones(37, 53, 'single'), [11 17]); p(max(abs(double(a(:)) - double(single(0.7))))); "
                 "p(imresize(1:4, [1 8])); p(size(imresize(zeros(30, 40, 10, 'single'), [15 15]))); "
                 "m = rand(300, 300); n = imresize(m, [50 50], 'nearest'); p(isequal(n, m(4:6:300, 4:6:300)));")
    assert out[0] == 0
    assert out[1] == 0.90625 and out[8] == 5 - 0.90625
    np.testing.assert_allclose(out[1:9], out[8:0:-1][::-1], atol=0)
    assert list(out[9:12]) == [15, 15, 10]
    assert out[12] == 1


def test_imresize_rounds_integer_images_after_each_pass():
    """imresizemex returns the input's class after each dimension: a uint8 image is rounded
    between the two passes (here the rows, whose scale is the smaller, go first)."""
    out = octave("x = uint8(mod((1:23)' * (1:29), 251)); y = imresize(x, [7 13], 'bilinear'); "
                 "r = imresize(double(x), [7 29], 'bilinear'); z = imresize(round(r), [7 13], 'bilinear'); "
                 "u = imresize(r, [7 13], 'bilinear'); "
                 "p(isequal(double(y), round(z))); p(isa(y, 'uint8')); p(isequal(double(y), round(u)));")
    assert list(out) == [1, 1, 0]


def test_ifft_symmetric_takes_the_first_half_as_matlab_does():
    """ifft(X, 'symmetric') of a spectrum that is not conjugate-symmetric: the inverse of the
    completion of its first half (the real part of the plain inverse would average both halves)."""
    out = octave("x = [1 2 3 4 5]; X = fft(x); p(ifft(X, 'symmetric')); "
                 "Y = X; Y(5) = Y(5) + 1i; Y(4) = 7; h = ifft(Y, 'symmetric'); "
                 "Z = Y; Z(4) = conj(Y(3)); Z(5) = conj(Y(2)); p(max(abs(h - real(ifft(Z))))); "
                 "p(max(abs(h - real(builtin('ifft', Y)))) > 0.1); p(ifft([1 2; 3 4])(:)');")
    np.testing.assert_allclose(out[:5], [1, 2, 3, 4, 5], atol=1e-12)
    assert out[5] < 1e-12 and out[6] == 1
    np.testing.assert_allclose(out[7:], np.fft.ifft([[1, 2], [3, 4]], axis=0).real.T.ravel(), atol=1e-12)
