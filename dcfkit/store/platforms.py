"""The platform a run's arithmetic depends on: processor, SIMD level, numerical libraries.

dcfkit's boxes are the same on every platform except where docs/architecture.md ("Same boxes
on every machine") says why not; this record lets a reader tell that two result folders came
from different platforms. Results sidecars and report provenance carry :func:`record`, and
``dcfkit compare`` prints :func:`differences`.
"""
from __future__ import annotations

import contextlib
import functools
import os
import platform
from importlib import metadata

from threadpoolctl import threadpool_info

from dcfkit.errors import printable

try:
    from numpy._core import _multiarray_umath as _umath
except ImportError:  # numpy 1.x
    from numpy.core import _multiarray_umath as _umath

__all__ = ["cpu_model", "describe", "differences", "record"]

# packages whose builds decide last bits: FFTs, BLAS, resizing, compiled loops, JPEG decoding
LIBRARIES = {"numpy": "numpy", "scipy": "scipy", "opencv": "opencv-contrib-python-headless",
             "numba": "numba", "llvmlite": "llvmlite", "pyfftw": "pyFFTW", "simplejpeg": "simplejpeg"}
OPENCV_WHEELS = ("opencv-contrib-python-headless", "opencv-contrib-python", "opencv-python-headless",
                 "opencv-python")
# environment variables that switch SIMD paths or BLAS kernels
SWITCHES = ("NPY_DISABLE_CPU_FEATURES", "NPY_ENABLE_CPU_FEATURES", "OPENBLAS_CORETYPE", "OPENCV_CPU_DISABLE",
            "NUMBA_CPU_NAME", "NUMBA_CPU_FEATURES", "GLIBC_TUNABLES", "JSIMD_FORCENONE")


def cpu_model() -> str:
    """The processor's model name with its family and model numbers (Linux: two processors of
    one name may differ, as their SSE estimates do), else what :mod:`platform` knows."""
    fields = {}
    with contextlib.suppress(OSError):
        with open("/proc/cpuinfo", encoding="utf-8", errors="replace") as info:
            for line in info:
                key, _, value = line.partition(":")
                if not key.strip():
                    break  # the first processor's block ends
                fields.setdefault(key.strip(), value.strip())
    name = fields.get("model name") or platform.processor() or platform.machine()
    numbers = [f"{key} {fields[key]}" for key in ("cpu family", "model") if key in fields]
    return f"{name} ({', '.join(numbers)})" if numbers else name


@functools.lru_cache(maxsize=1)
def record() -> dict:
    """``{"arch", "cpu", "simd", "blas", "libc", "libraries", "switches"}``: the processor and
    numpy's SIMD targets in use, the BLAS (library, version, kernel) numpy calls, the C library,
    the versions of the numerical packages, and the environment switches that are set."""
    return {"arch": platform.machine(), "cpu": cpu_model(), "simd": _numpy_simd(), "blas": _blas(),
            "libc": " ".join(platform.libc_ver()).strip() or platform.system(),
            "libraries": {key: _version(key) for key in LIBRARIES},
            "switches": {name: os.environ[name] for name in SWITCHES if name in os.environ}}


def describe(rec) -> str:
    """One line of a :func:`record` (or ``"not recorded"``); characters that are not printable (a
    line break in an environment value) escaped."""
    if not isinstance(rec, dict):
        return "not recorded"
    libs = rec.get("libraries") if isinstance(rec.get("libraries"), dict) else {}
    parts = [f"{rec.get('arch', '?')} {rec.get('cpu', '?')}", f"SIMD {rec.get('simd', '?')}",
             *(f"{k} {v}" for k, v in libs.items() if v), f"BLAS {rec.get('blas', '?')}", str(rec.get("libc", "?"))]
    switches = rec.get("switches") if isinstance(rec.get("switches"), dict) else {}
    parts += [f"{k}={v}" for k, v in switches.items()]
    return printable(", ".join(parts))


def differences(a, b) -> list[str]:
    """What differs between two records, one ``"key: a -> b"`` each (libraries and switches
    key by key, each one line as :func:`describe`'s); empty when either is missing or they agree."""
    if not isinstance(a, dict) or not isinstance(b, dict):
        return []
    out = []
    for key in ("arch", "cpu", "simd", "blas", "libc"):
        if a.get(key) != b.get(key):
            out.append(printable(f"{key}: {a.get(key)} -> {b.get(key)}"))
    for group in ("libraries", "switches"):
        ga, gb = a.get(group) or {}, b.get(group) or {}
        if isinstance(ga, dict) and isinstance(gb, dict):
            out += [printable(f"{k}: {ga.get(k)} -> {gb.get(k)}") for k in sorted(set(ga) | set(gb))
                    if ga.get(k) != gb.get(k)]
    return out


def _version(key: str) -> str | None:
    for dist in OPENCV_WHEELS if key == "opencv" else (LIBRARIES[key],):
        with contextlib.suppress(metadata.PackageNotFoundError):
            return metadata.version(dist)
    return None


def _numpy_simd() -> str:
    """numpy's baseline and the dispatch targets it found (np.show_runtime's lists)."""
    found = [t for t in _umath.__cpu_dispatch__ if _umath.__cpu_features__.get(t)]
    return " ".join([*_umath.__cpu_baseline__, *found]) or "none"


def _blas() -> str:
    """numpy's BLAS (loaded with numpy) as threadpoolctl reads it: name, version, kernel."""
    blas = sorted((i for i in threadpool_info() if i.get("user_api") == "blas"),
                  key=lambda i: ("numpy" not in str(i.get("filepath", "")), str(i.get("filepath", ""))))
    if not blas:
        return "unknown"
    info = blas[0]  # numpy's: scipy, OpenCV and others may load BLAS libraries of their own, in any order
    return " ".join(str(p) for p in (info.get("internal_api"), info.get("version"), info.get("architecture")) if p)
