"""The SSE reciprocal and reciprocal-square-root estimates (``rcpps``, ``rsqrtps``) that Piotr's
``gradientMex`` takes for the gradient magnitude, computed the same way on every machine.

Intel documents only their bound (relative error at most 1.5 · 2⁻¹²); each processor family
has its own values. :func:`rcp` and :func:`rsqrt` follow the rule of Intel's tables as the
Bochs emulator documents it: the reciprocal (square root) of the middle of the input's
2⁻¹¹-wide (2⁻¹⁰-wide) mantissa interval, rounded to nearest at 12 fraction bits. It is
not checked here against an Intel processor. :func:`cpu_rcp` and :func:`cpu_rsqrt` run this
processor's own instructions (x86 only).
"""
from __future__ import annotations

import functools
import platform

import numba
import numpy as np
from llvmlite import ir
from numba import types
from numba.extending import intrinsic

__all__ = ["cpu_available", "cpu_rcp", "cpu_rsqrt", "estimate_tables", "rcp", "rsqrt"]

_SIGN, _EXP, _MANT = np.uint32(0x80000000), np.uint32(0x7F800000), np.uint32(0x007FFFFF)


@functools.lru_cache(maxsize=1)
def estimate_tables() -> tuple[np.ndarray, np.ndarray]:
    """``(rcp, rsqrt)`` mantissa tables, uint32 result fraction bits in place (``<< 23`` form):
    ``rcp`` (2048,) by the top 11 fraction bits; ``rsqrt`` (2, 1024) by the biased exponent's
    parity and the top 10 fraction bits."""
    mid = 1.0 + (2 * np.arange(2048) + 1) / 4096.0
    rcp_table = np.rint((2.0 / mid - 1.0) * 4096).astype(np.uint32) << np.uint32(11)
    mid = 1.0 + (2 * np.arange(1024) + 1) / 2048.0
    # an even biased exponent leaves 2·mid under the root, an odd one mid (127 is odd)
    rsqrt_table = np.stack([2.0 / np.sqrt(2.0 * mid) - 1.0, 2.0 / np.sqrt(mid) - 1.0])
    rsqrt_table = np.rint(rsqrt_table * 4096).astype(np.uint32) << np.uint32(11)
    for table in (rcp_table, rsqrt_table):
        table.setflags(write=False)
    return rcp_table, rsqrt_table


def _float32(x) -> tuple[np.ndarray, np.ndarray]:
    a = np.array(x, np.float32, ndmin=1, order="C")
    return a, a.view(np.uint32)


def rcp(x: np.ndarray) -> np.ndarray:
    """``rcpps`` of float32 ``x``, elementwise: ±0 and subnormals give ±inf, ±inf gives ±0,
    results below the normal range are flushed to ±0, NaN stays NaN."""
    a, b = _float32(x)
    exp = ((b & _EXP) >> np.uint32(23)).astype(np.int64)
    out_exp = 253 - exp
    normal = (exp > 0) & (exp < 255) & (out_exp > 0)
    mant = estimate_tables()[0][(b >> np.uint32(12)) & np.uint32(0x7FF)]
    out = (b & _SIGN) | np.where(normal, (out_exp.astype(np.uint32) << np.uint32(23)) | mant, np.uint32(0))
    out = out.view(np.float32)
    out[exp == 0] = np.copysign(np.inf, a[exp == 0])
    out[np.isnan(a)] = np.nan
    return out.reshape(np.shape(x))


def rsqrt(x: np.ndarray) -> np.ndarray:
    """``rsqrtps`` of float32 ``x``, elementwise: ±0 and subnormals give ±inf, +inf gives 0,
    negative numbers and NaN give NaN."""
    a, b = _float32(x)
    exp = ((b & _EXP) >> np.uint32(23)).astype(np.int64)
    out_exp = 0x7E - ((exp - 0x7F) >> 1)
    mant = estimate_tables()[1][exp & 1, (b >> np.uint32(13)) & np.uint32(0x3FF)]
    out = ((out_exp.astype(np.uint32) << np.uint32(23)) | mant).view(np.float32)
    out[exp == 0] = np.copysign(np.inf, a[exp == 0])
    out[exp == 255] = 0.0
    out[(a < 0) | np.isnan(a)] = np.nan
    return out.reshape(np.shape(x))


def cpu_available() -> bool:
    """Whether this machine has the SSE estimate instructions (x86)."""
    return platform.machine().lower() in ("x86_64", "amd64", "i686", "x86")


def cpu_rcp(x: np.ndarray) -> np.ndarray:
    """This processor's ``rcpss`` of float32 ``x``, elementwise (x86 only)."""
    return _on_this_cpu(_cpu_rcp, x)


def cpu_rsqrt(x: np.ndarray) -> np.ndarray:
    """This processor's ``rsqrtss`` of float32 ``x``, elementwise (x86 only)."""
    return _on_this_cpu(_cpu_rsqrt, x)


def _on_this_cpu(kernel, x) -> np.ndarray:
    if not cpu_available():
        raise RuntimeError("fhog arithmetic 'sse_cpu' needs an x86 processor (SSE rsqrt/rcp instructions); "
                           "'sse' computes the same estimates on any machine")
    a = np.array(x, np.float32, ndmin=1, order="C")
    return kernel(a.reshape(-1)).reshape(np.shape(x))


def _sse_scalar(name: str):
    """A float32 -> float32 intrinsic applying the x86 instruction ``name`` to lane 0 (compiled
    only when a kernel using it is first called, so it is harmless on other processors)."""
    @intrinsic
    def call(typingctx, x):  # pragma: no cover - compiled
        def codegen(context, builder, signature, args):
            v4 = ir.VectorType(ir.FloatType(), 4)
            fn = builder.module.declare_intrinsic(name, fnty=ir.FunctionType(v4, [v4]))
            zero = ir.Constant(ir.IntType(32), 0)
            vec = builder.insert_element(ir.Constant(v4, ir.Undefined), args[0], zero)
            return builder.extract_element(builder.call(fn, [vec]), zero)

        return types.float32(types.float32), codegen

    return call


_rcp_ss, _rsqrt_ss = _sse_scalar("llvm.x86.sse.rcp.ss"), _sse_scalar("llvm.x86.sse.rsqrt.ss")


@numba.njit(nogil=True)
def _cpu_rcp(x):  # pragma: no cover - compiled
    out = np.empty_like(x)
    for i in range(x.size):
        out[i] = _rcp_ss(x[i])
    return out


@numba.njit(nogil=True)
def _cpu_rsqrt(x):  # pragma: no cover - compiled
    out = np.empty_like(x)
    for i in range(x.size):
        out[i] = _rsqrt_ss(x[i])
    return out
