"""How far does the platform move dcfkit's boxes? One source of platform-dependent arithmetic
switched at a time, each in a fresh process, against a baseline run.

    python benchmarks/platform_noise.py                          # every shipped config and preset, 8 dev sequences
    python benchmarks/platform_noise.py --configs strcf,reference/strcf --switches baseline,blas_skylakex
    python benchmarks/platform_noise.py --max-frames 5 --json noise.json   # a smoke run

A switch simulates a platform this machine is not: another SIMD level of numpy's loops
(``numpy_avx2``: no AVX-512; ``numpy_sse42``: no AVX2 either), another OpenBLAS kernel, OpenCV
and libjpeg-turbo without their SIMD paths, numba compiled for a generic x86-64, glibc's
math without its FMA variants, pyFFTW instead of scipy's FFT, and this processor's own SSE
estimates in fhog's 'sse' arithmetic (another processor family computes other values).
For each config and sequence it prints the first frame whose box differs from the baseline's
in any bit (``-``: identical), the largest difference of a box coordinate and the change of
precision and AUC (OTB protocol); then per config the sequences that part and the largest
and mean |ΔAUC|. ``--runs DIR`` keeps each switch's boxes there and reuses them. Sequences: the development data
(``../shared/data`` or ``$DCFKIT_TEST_DATA``), else a synthetic one.
"""
import os

for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(var, "1")

import argparse  # noqa: E402
import json  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

DATA = Path(os.environ.get("DCFKIT_TEST_DATA", Path(__file__).resolve().parents[2] / "shared" / "data"))
DEV = (("uav123_10fps", "UAV123_10fps", None), ("dtb70", "DTB70", ["Gull1"]), ("uavdt", "UAVDT", ["S0601"]))
CONFIGS = ("kcf", "dsst", "strcf", "bacf", "arcf", "autotrack", "dr2track",
           "reference/strcf", "reference/bacf", "reference/dr2track")
# switch -> (environment, what the worker changes in each config); environments follow each
# library's documented switch
SWITCHES = {
    "baseline": ({}, None),
    "sse_cpu": ({}, "sse_cpu"),
    "fft_pyfftw": ({}, "pyfftw"),
    "numpy_avx2": ({"NPY_DISABLE_CPU_FEATURES": "X86_V4 AVX512_ICL"}, None),
    "numpy_sse42": ({"NPY_DISABLE_CPU_FEATURES": "X86_V3 X86_V4 AVX512_ICL"}, None),
    "blas_skylakex": ({"OPENBLAS_CORETYPE": "SkylakeX"}, None),
    "blas_prescott": ({"OPENBLAS_CORETYPE": "Prescott"}, None),
    "opencv_sse2": ({"OPENCV_CPU_DISABLE": "AVX512-SKX,AVX2,FP16,AVX,SSE4.2,SSE4.1"}, None),
    "jpeg_no_simd": ({"JSIMD_FORCENONE": "1"}, None),
    "numba_generic": ({"NUMBA_CPU_NAME": "generic"}, None),
    "libm_no_fma": ({"GLIBC_TUNABLES": "glibc.cpu.hwcaps=-AVX2,-FMA,-AVX512F"}, None),
}


def sequences(max_frames: int | None):
    """(name, frame reader, 0-based ground truth) of the development sequences, or a synthetic one."""
    from dcfkit.datasets import load_dataset

    out = []
    for dataset, folder, names in DEV:
        if (DATA / folder).is_dir():
            out += [(s.name, s.frame, s.ground_truth) for s in load_dataset(dataset, DATA / folder, names)]
    if not out:
        from dcfkit.datasets.synthetic import make_sequence

        syn = make_sequence(n_frames=40)
        out = [("synthetic", syn.frames.__getitem__, syn.ground_truth)]
    return [(n, read, gt[:max_frames] if max_frames else gt) for n, read, gt in out]


def switched(config: dict, change: str | None) -> dict:
    """``config`` with fhog's 'sse' arithmetic as 'sse_cpu', or with the pyFFTW backend."""
    if change == "pyfftw":
        return {**config, "tracker": {**(config.get("tracker") or {}), "fft_backend": "pyfftw"}}
    if change == "sse_cpu":
        feats = [dict(f, arithmetic="sse_cpu") if isinstance(f, dict) and f.get("arithmetic") == "sse" else f
                 for f in config.get("features") or []]
        scale = dict(config.get("scale") or {})
        if scale.get("fhog_arithmetic") == "sse":
            scale["fhog_arithmetic"] = "sse_cpu"
        return {**config, "features": feats, **({"scale": scale} if scale else {})}
    return config


def work(args) -> int:
    """The worker: every config on every sequence, boxes saved to ``args.worker`` (npz)."""
    import cv2

    import dcfkit
    from dcfkit.config import load_config
    from dcfkit.experiments.loop import track

    cv2.setNumThreads(1)
    boxes = {}
    for name, read, gt in sequences(args.max_frames):
        for config in args.configs.split(","):
            tracker = dcfkit.load_tracker(switched(load_config(config), args.change))
            boxes[f"{name}|{config}"] = track(tracker, (read(i) for i in range(len(gt))), gt[0]).boxes
    partial = Path(args.worker).with_suffix(".partial.npz")
    np.savez(partial, **boxes)
    partial.replace(args.worker)  # a killed run leaves no file that looks complete
    return 0


def run_switch(name: str, args, folder: Path) -> Path | None:
    env, change = SWITCHES[name]
    out = folder / f"{name}.npz"
    if out.is_file():
        return out
    command = [sys.executable, __file__, "--worker", str(out), "--configs", args.configs]
    if args.max_frames:
        command += ["--max-frames", str(args.max_frames)]
    if change:
        command += ["--change", change]
    full_env = {**os.environ, **env}
    if name == "numba_generic":  # numba's cache holds this processor's machine code
        full_env["NUMBA_CACHE_DIR"] = str(folder / "numba_cache")
    status = subprocess.run(command, env=full_env).returncode
    if status != 0:  # e.g. a BLAS kernel beyond this processor's instruction set
        print(f"\n== {name}: not run here (its process exited with status {status})")
        return None
    return out


def compare(base: dict, other: dict, gts: dict) -> list[dict]:
    from dcfkit.analysis import metrics

    rows = []
    for key in base:
        seq, config = key.split("|")
        a, b, gt = base[key], other[key], gts[seq]
        same = (a == b) | (np.isnan(a) & np.isnan(b))
        differ = np.any(~same, axis=1)
        sa, sb = metrics.score_sequence(a, gt, protocol="otb"), metrics.score_sequence(b, gt, protocol="otb")
        gap = np.where(same, 0.0, np.abs(a - b))
        rows.append({"config": config, "sequence": seq,
                     "parts_at": int(np.argmax(differ)) + 1 if differ.any() else None,
                     "max_px": float(np.nan_to_num(gap, nan=np.inf).max()),
                     "d_precision": sb["precision"] - sa["precision"], "d_auc": sb["auc"] - sa["auc"]})
    return rows


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--configs", default=",".join(CONFIGS))
    parser.add_argument("--switches", default=",".join(SWITCHES), help=f"of: {', '.join(SWITCHES)}")
    parser.add_argument("--max-frames", type=int, default=None, help="track only the first N frames of each sequence")
    parser.add_argument("--json", default=None, help="also write every row and summary here")
    parser.add_argument("--runs", type=Path, default=None,
                        help="keep each switch's boxes in this folder and reuse those already there (default: a temp dir)")
    parser.add_argument("--worker", help=argparse.SUPPRESS)
    parser.add_argument("--change", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        return work(args)
    names = [s for s in args.switches.split(",") if s]
    unknown = [s for s in names if s not in SWITCHES]
    if unknown:
        parser.error(f"unknown switch(es) {', '.join(unknown)}; choose from {', '.join(SWITCHES)}")
    gts = {n: g for n, _, g in sequences(args.max_frames)}
    report = {}
    with tempfile.TemporaryDirectory() as tmp:
        folder = args.runs or Path(tmp)
        folder.mkdir(parents=True, exist_ok=True)
        baseline = run_switch("baseline", args, folder)
        if baseline is None:
            return 1
        base = dict(np.load(baseline))
        for name in (n for n in names if n != "baseline"):
            boxes = run_switch(name, args, folder)
            if boxes is None:
                continue
            rows = compare(base, dict(np.load(boxes)), gts)
            report[name] = rows
            print(f"\n== {name}: {' '.join(f'{k}={v}' for k, v in SWITCHES[name][0].items()) or SWITCHES[name][1]}")
            print(f"{'config':<20} {'sequence':<12} {'parts at':>8} {'max px':>8} {'d_prec':>8} {'d_auc':>8}")
            for r in rows:
                print(f"{r['config']:<20} {r['sequence']:<12} {r['parts_at'] or '-':>8} {r['max_px']:>8.2g} "
                      f"{r['d_precision']:>+8.3f} {r['d_auc']:>+8.3f}")
            for config in dict.fromkeys(r["config"] for r in rows):
                mine = [r for r in rows if r["config"] == config]
                d = np.abs([r["d_auc"] for r in mine])
                print(f"  {config}: {sum(r['parts_at'] is not None for r in mine)} of {len(mine)} sequences part, "
                      f"by up to {max(r['max_px'] for r in mine):.2g} px, |d_auc| max {d.max():.3f} mean {d.mean():.3f}, "
                      f"|d_prec| max {np.abs([r['d_precision'] for r in mine]).max():.3f}")
    if args.json:
        Path(args.json).write_text(json.dumps(report, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
