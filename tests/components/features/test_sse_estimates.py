"""The portable SSE estimates of fhog's 'sse' arithmetic (dcfkit.components.features.sse_estimates) and its
acos table: hand-computed values, the documented error bound over every mantissa, the same
values from the C++ header that the authors' code is built with under Octave."""
import math
import platform
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from dcfkit.components.features import sse_estimates
from dcfkit.components.features.fhog_sse import acos_table

HEADER = Path(__file__).resolve().parents[3] / "benchmarks" / "octave" / "portable_estimates.hpp"
X86 = platform.machine().lower() in ("x86_64", "amd64")


def bits(values):
    return [int(b) for b in np.asarray(values, np.float32).view(np.uint32).ravel()]


def every_mantissa(exponent_bits: int) -> np.ndarray:
    return (np.arange(2**23, dtype=np.uint32) | np.uint32(exponent_bits << 23)).view(np.float32)


def test_hand_computed_estimates():
    # rcp(1.0): interval [1, 1 + 2^-11), middle 1 + 2^-12; 2/(1 + 2^-12) - 1 = 0.99951..., x4096 = 4094.0
    # -> fraction 4094/4096 at exponent -1: 0.999755859375 = 0x3F7FF000 (Intel's documented rcpss(1.0))
    # rcp(1.5): middle 1.5 + 2^-12; 2/1.500244 - 1 = 0.333116, x4096 = 1364.4 -> 1364 -> 0x3F2AA000
    # rsqrt(1.0): odd biased exponent, middle 1 + 2^-11: 2/sqrt(1.000488) - 1 = 0.99951, x4096 = 4094 -> 0x3F7FF000
    # rsqrt(2.0): even biased exponent, 2/sqrt(2 (1 + 2^-11)) - 1 = 0.413868, x4096 = 1695.2 -> 1695 = 0x69F,
    # fraction 0x69F << 11 = 0x34F800 at exponent -1 -> 0x3F34F800
    assert bits(sse_estimates.rcp([1.0, 1.5, -2.0])) == [0x3F7FF000, 0x3F2AA000, 0xBEFFF000]
    assert bits(sse_estimates.rsqrt([1.0, 2.0, 4.0])) == [0x3F7FF000, 0x3F34F800, 0x3EFFF000]


def test_special_values():
    x = np.array([0.0, -0.0, 1e-40, np.inf, -np.inf, np.nan, 3e38], np.float32)
    with np.errstate(all="ignore"):
        r = sse_estimates.rcp(x)
    assert np.array_equal(r[:4], [np.inf, -np.inf, np.inf, 0.0]) and r[4] == 0 and np.signbit(r[4])
    assert np.isnan(r[5]) and r[6] == 0  # 1/3e38 is below the normal range: flushed
    s = sse_estimates.rsqrt(np.array([0.0, 1e-40, np.inf, -1.0, np.nan], np.float32))
    assert s[0] == np.inf and s[1] == np.inf and s[2] == 0 and np.isnan(s[3]) and np.isnan(s[4])
    assert sse_estimates.rcp(np.float32(2.0)).shape == () and sse_estimates.rsqrt(np.ones((2, 3))).shape == (2, 3)


@pytest.mark.parametrize("exponent", [127, 128, 200])
def test_error_bound_over_every_mantissa(exponent):
    """Intel's bound, |relative error| <= 1.5 * 2^-12, for all 2^23 mantissas of an odd and an even
    exponent; each estimate depends on the top 11 (rcp) or 10 (rsqrt) fraction bits only."""
    x = every_mantissa(exponent)
    r, s = sse_estimates.rcp(x), sse_estimates.rsqrt(x)
    x64 = x.astype(np.float64)
    assert np.abs(r * x64 - 1).max() <= 1.5 * 2**-12
    assert np.abs(s * np.sqrt(x64) - 1).max() <= 1.5 * 2**-12
    assert np.all(np.diff(r.reshape(2048, -1), axis=1) == 0)
    assert np.all(np.diff(s.reshape(1024, -1), axis=1) == 0)
    assert np.all(np.diff(r) <= 0) and np.all(np.diff(s) <= 0)


@pytest.mark.skipif(shutil.which("g++") is None, reason="needs g++ to build the Octave-side header")
def test_octave_header_computes_the_same_estimates(tmp_path):
    """benchmarks/octave/portable_estimates.hpp, which authors_octave.sh builds into gradientMex,
    against this module, over every mantissa of two exponents and the special values."""
    source = tmp_path / "check.cpp"
    source.write_text(f'#include "{HEADER}"\n' + r'''
#include <cstdio>
int main() {
  unsigned exps[] = {127u, 128u};
  for (unsigned e : exps) for (uint32_t m = 0; m < (1u << 23); ++m) {
    float x = dcfkit_estimates::value((e << 23) | m);
    uint32_t pair[2] = {dcfkit_estimates::bits(dcfkit_estimates::rcp(x)), dcfkit_estimates::bits(dcfkit_estimates::rsqrt(x))};
    fwrite(pair, 4, 2, stdout);
  }
  float special[] = {0.0f, 1e-40f, 1e38f, -3.0f};
  for (float x : special) {
    uint32_t pair[2] = {dcfkit_estimates::bits(dcfkit_estimates::rcp(x)), dcfkit_estimates::bits(dcfkit_estimates::rsqrt(x))};
    fwrite(pair, 4, 2, stdout);
  }
}
''')
    binary = tmp_path / "check"
    subprocess.run(["g++", "-O2", "-o", str(binary), str(source)], check=True)
    out = np.frombuffer(subprocess.run([str(binary)], check=True, capture_output=True).stdout, np.uint32)
    out = out.reshape(-1, 2)
    x = np.concatenate([every_mantissa(127), every_mantissa(128), np.array([0.0, 1e-40, 1e38, -3.0], np.float32)])
    with np.errstate(all="ignore"):
        expected = np.stack([sse_estimates.rcp(x).view(np.uint32), sse_estimates.rsqrt(x).view(np.uint32)], 1)
    nan = np.isnan(expected.view(np.float32)) & np.isnan(out.view(np.float32))
    assert np.all((out == expected) | nan)


def test_acos_table_is_correctly_rounded():
    """Each entry is the float32 nearest to acos(i/10000f): acos (in float64) lies between the
    midpoints to its float32 neighbours. Below i = 1000 (padding π included) they are capped at
    π - 1e-6, as Piotr's."""
    table = acos_table()
    i = np.arange(-10000, 10000)
    x = (i.astype(np.float32) / np.float32(10000)).astype(np.float32)
    core = table[10:-10]
    exact = np.array([math.acos(float(v)) for v in x])
    lower = np.nextafter(core, np.float32(-np.inf)).astype(np.float64)
    upper = np.nextafter(core, np.float32(np.inf)).astype(np.float64)
    free = i >= 1000
    assert np.all((exact[free] >= (lower[free] + core[free]) / 2) & (exact[free] <= (upper[free] + core[free]) / 2))
    cap = np.float32(np.float32(3.14159265) - np.float32(1e-6))
    assert np.all(core[~free] <= cap) and np.all(table[:10] == cap) and not table[-10:].any()


@pytest.mark.skipif(not X86, reason="the processor's estimates need x86-64")
def test_cpu_estimates_meet_the_bound():
    x = every_mantissa(127)
    r, s = sse_estimates.cpu_rcp(x), sse_estimates.cpu_rsqrt(x)
    assert np.abs(r * x.astype(np.float64) - 1).max() <= 1.5 * 2**-12
    assert np.abs(s * np.sqrt(x.astype(np.float64)) - 1).max() <= 1.5 * 2**-12


@pytest.mark.skipif(X86, reason="checks the message on processors without SSE")
def test_cpu_estimates_refused_off_x86():
    with pytest.raises(RuntimeError, match="'sse' computes the same estimates on any machine"):
        sse_estimates.cpu_rcp(np.ones(3, np.float32))
