"""Time and peak memory of the statistics, ``compare`` and ``report`` on many synthetic sequences.

    python benchmarks/stats_scale.py [--sequences 30000] [--small 3000] [--frames 20] [--json out.json]

GOT-10k has 9,335 sequences and TrackingNet 30,132. No tracking is done: two trackers' result
files (boxes the ground truth plus noise, dcfkit sidecars whose platform record differs per
sequence) are written for ``--small`` and for ``--sequences`` synthetic sequences, then each stage
runs in a fresh process, which reports its time and its peak resident memory (the process's
high-water mark, and how much the stage added to what the imports and the sequences took):

* ``statistics``: :func:`mean_interval`, :func:`paired_difference` and :func:`versus_baseline`
  (two trackers, two scores) on per-sequence scores;
* ``compare``: :func:`compare_folders` of the two result folders;
* ``report``: :func:`write_report` (tables, ``report.json``, the two plots) of both trackers.

The last lines are the ratios of time and of added memory between the two sizes: about
``sequences / small`` for a stage linear in the sequences. The HTML page (``--html``) is left
out: it shows every sequence's frames, so it needs images.
"""
import argparse
import json
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from dcfkit.analysis.compare import compare_folders
from dcfkit.analysis.report import write_report
from dcfkit.analysis.statistics import mean_interval, paired_difference, versus_baseline
from dcfkit.datasets import Sequence
from dcfkit.store.files import checksum, format_boxes

STAGES = ("statistics", "compare", "report")
TRACKERS = {"kcf": 4.0, "strcf": 2.0}  # tracker -> the boxes' noise (pixels)


def sequences(n: int, frames: int) -> list[Sequence]:
    """``n`` synthetic sequences of ``frames`` frames: a 20 x 20 box drifting, seeded."""
    rng = np.random.default_rng(0)
    frame_paths = (Path("00000001.jpg"),) * frames  # never read: scoring needs the ground truth only
    out = []
    for k in range(n):
        gt = np.empty((frames, 4))
        gt[:, :2] = 50 + np.cumsum(rng.normal(0, 2, (frames, 2)), axis=0)
        gt[:, 2:] = 20
        out.append(Sequence(name=f"seq{k:05d}", frames=frame_paths, ground_truth=gt, attributes={}, dataset="test"))
    return out


def write_results(out: Path, seqs: list[Sequence]) -> None:
    """Each tracker's ``<sequence>.txt`` and sidecar, as ``ResultStore.write`` lays them out (without
    its fsync per file, which would take most of the time here)."""
    rng = np.random.default_rng(1)
    for tracker, noise in TRACKERS.items():
        folder = out / tracker
        folder.mkdir(parents=True)
        for k, seq in enumerate(seqs):
            text = format_boxes(seq.ground_truth + rng.normal(0, noise, seq.ground_truth.shape) * [1, 1, 0, 0])
            (folder / f"{seq.name}.txt").write_text(text)
            meta = {"run_key": tracker, "fps": 100.0, "frames": len(seq), "sha256": checksum(text.encode()),
                    "platform": {"arch": "x86_64", "cpu": f"CPU {tracker} {k}", "libraries": {"numpy": "2"}}}
            (folder / f"{seq.name}.json").write_text(json.dumps(meta))


def run_stage(stage: str, work: Path, n: int, frames: int) -> dict:
    """Run ``stage`` on the first ``n`` sequences (this process); its seconds and memory."""
    seqs = sequences(n, frames)
    rng = np.random.default_rng(2)
    scores = {t: rng.random(n) for t in TRACKERS}
    base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    start = time.perf_counter()
    if stage == "statistics":
        a, b = scores.values()
        mean_interval(a)
        paired_difference(a, b)
        rows = [{"tracker": t, "sequence": s.name, "auc": v, "precision": 1 - v}
                for t, values in scores.items() for s, v in zip(seqs, values)]
        versus_baseline(rows, list(TRACKERS), ("auc", "precision"))
    elif stage == "compare":
        compare_folders(work / "out" / "kcf", work / "out" / "strcf", seqs)
    else:
        write_report(work / "out", seqs, report_dir=work / "report")
    seconds = time.perf_counter() - start
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    return {"stage": stage, "sequences": n, "seconds": seconds, "peak_mb": peak, "added_mb": peak - base}


def measure(stage: str, work: Path, n: int, frames: int) -> dict:
    """:func:`run_stage` in a fresh process, so that its peak memory is its own."""
    out = subprocess.run([sys.executable, __file__, "--stage", stage, "--work", str(work), "--sequences", str(n),
                          "--frames", str(frames)], check=True, capture_output=True, text=True)
    return json.loads(out.stdout.splitlines()[-1])


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sequences", type=int, default=30_000)
    parser.add_argument("--small", type=int, default=3_000, help="the smaller size, for the ratios")
    parser.add_argument("--frames", type=int, default=20, help="frames per sequence")
    parser.add_argument("--work", type=Path, help="folder for the result files (default: a temporary one)")
    parser.add_argument("--stage", choices=STAGES, help=argparse.SUPPRESS)  # one stage in this process
    parser.add_argument("--json", help="write the measurements here")
    args = parser.parse_args()
    if args.stage:
        print(json.dumps(run_stage(args.stage, args.work, args.sequences, args.frames)))
        return
    with tempfile.TemporaryDirectory() as tmp:
        work = args.work or Path(tmp)
        found = []
        for n in (args.small, args.sequences):
            folder = work / f"n{n}"
            write_results(folder / "out", sequences(n, args.frames))
            for stage in STAGES:
                found.append(measure(stage, folder, n, args.frames))
                r = found[-1]
                print(f"{stage:<10} {n:>7,} sequences: {r['seconds']:7.2f} s ({n / r['seconds']:,.0f} sequences/s), "
                      f"peak RSS {r['peak_mb']:6.0f} MB, {r['added_mb']:+6.0f} MB by the stage", flush=True)
    for stage in STAGES:
        small, large = (r for r in found if r["stage"] == stage)
        print(f"{stage:<10} {args.sequences / args.small:g}x the sequences: {large['seconds'] / small['seconds']:.1f}x "
              f"the time, {large['added_mb'] / max(small['added_mb'], 1):.1f}x the added memory "
              f"({small['added_mb']:.0f} -> {large['added_mb']:.0f} MB)")
    if args.json:
        Path(args.json).write_text(json.dumps(found, indent=1) + "\n")


if __name__ == "__main__":
    main()
