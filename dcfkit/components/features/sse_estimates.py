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

__all__ = ["cpu_available", "cpu_rcp", "cpu_rsqrt", "estimate_tables", "rcp", "rcp_one", "rsqrt", "rsqrt_one"]


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


@intrinsic
def _bits(typingctx, x):  # pragma: no cover - compiled
    """The bits of a float32 as a uint32."""
    def codegen(context, builder, signature, args):
        return builder.bitcast(args[0], ir.IntType(32))

    return types.uint32(types.float32), codegen


@intrinsic
def _float(typingctx, b):  # pragma: no cover - compiled
    """The float32 whose bits are the uint32 ``b``."""
    def codegen(context, builder, signature, args):
        return builder.bitcast(args[0], ir.FloatType())

    return types.float32(types.uint32), codegen


@numba.njit(inline="always", nogil=True)
def rcp_one(x, table):  # pragma: no cover - compiled
    """``rcpss`` of one float32 by ``table`` (:func:`estimate_tables`)."""
    b = _bits(x)
    sign, exp = b & np.uint32(0x80000000), np.int64((b >> np.uint32(23)) & np.uint32(0xFF))
    if exp == 255:
        return x if (b & np.uint32(0x7FFFFF)) != 0 else _float(sign)  # NaN stays, ±inf -> ±0
    if exp == 0:
        return _float(sign | np.uint32(0x7F800000))  # ±0 and subnormals -> ±inf
    if exp > 252:
        return _float(sign)  # below the normal range: flushed
    return _float(sign | np.uint32((253 - exp) << 23) | table[(b >> np.uint32(12)) & np.uint32(0x7FF)])


@numba.njit(inline="always", nogil=True)
def rsqrt_one(x, table):  # pragma: no cover - compiled
    """``rsqrtss`` of one float32 by ``table`` (:func:`estimate_tables`)."""
    b = _bits(x)
    exp = np.int64((b >> np.uint32(23)) & np.uint32(0xFF))
    if x != x or (exp > 0 and x < 0):
        return np.float32(np.nan)
    if exp == 0:
        return _float((b & np.uint32(0x80000000)) | np.uint32(0x7F800000))  # ±0, subnormals -> ±inf
    if exp == 255:
        return np.float32(0.0)
    out_exp = np.uint32(0x7E - ((exp - 0x7F) >> 1))
    return _float((out_exp << np.uint32(23)) | table[exp & 1, (b >> np.uint32(13)) & np.uint32(0x3FF)])


@numba.njit(nogil=True, cache=True)
def _rcp_all(x, table, out):  # pragma: no cover - compiled
    for i in range(x.size):
        out[i] = rcp_one(x[i], table)


@numba.njit(nogil=True, cache=True)
def _rsqrt_all(x, table, out):  # pragma: no cover - compiled
    for i in range(x.size):
        out[i] = rsqrt_one(x[i], table)


def _each(kernel, table, x) -> np.ndarray:
    a = np.ascontiguousarray(x, np.float32)
    out = np.empty_like(a)
    kernel(a.reshape(-1), table, out.reshape(-1))
    return out.reshape(np.shape(x))


def rcp(x) -> np.ndarray:
    """``rcpps`` of float32 ``x``, elementwise: ±0 and subnormals give ±inf, ±inf gives ±0,
    results below the normal range are flushed to ±0, NaN stays NaN."""
    return _each(_rcp_all, estimate_tables()[0], x)


def rsqrt(x) -> np.ndarray:
    """``rsqrtps`` of float32 ``x``, elementwise: ±0 and subnormals give ±inf, +inf gives 0,
    negative numbers and NaN give NaN."""
    return _each(_rsqrt_all, estimate_tables()[1], x)


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
    a = np.ascontiguousarray(x, np.float32)
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


def _elementwise(instruction):
    """A compiled loop applying ``instruction`` to each element of a float32 array."""
    @numba.njit(nogil=True)
    def apply(x):  # pragma: no cover - compiled
        out = np.empty_like(x)
        for i in range(x.size):
            out[i] = instruction(x[i])
        return out

    return apply


_cpu_rcp, _cpu_rsqrt = _elementwise(_rcp_ss), _elementwise(_rsqrt_ss)
