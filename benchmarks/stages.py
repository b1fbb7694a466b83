"""Per-stage time of one tracker per frame (patch extraction, each component method, FFTs,
peaks), by wrapping the tracker's arithmetic with timers as benchmarks/floor.py finds it — the
tracker code itself carries no instrumentation.

    python benchmarks/stages.py [--config dr2track] [--root ../shared/data/UAV123_10fps]
        [--sequence boat1] [--frames 100] [--synthetic] [--json stages.json]

Single-threaded; frames are decoded before timing. Synthetic 1280x720 frames with --synthetic
or when the real data is absent. Prints ms per frame per stage and its share of the total.
"""
import os

for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[var] = "1"

import argparse  # noqa: E402
import collections  # noqa: E402
import functools  # noqa: E402
import json  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import cv2  # noqa: E402

import dcfkit  # noqa: E402
from dcfkit.datasets.synthetic import make_sequence  # noqa: E402
from dcfkit.experiments.loop import track  # noqa: E402
from floor import arithmetic  # noqa: E402  (benchmarks/floor.py: one discovery of a tracker's arithmetic)

cv2.setNumThreads(1)
TOTALS = collections.defaultdict(float)


def timed(stage, fn):
    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        start = time.perf_counter()
        try:
            return fn(*args, **kwargs)
        finally:
            TOTALS[stage] += time.perf_counter() - start
    return wrapper


def instrument(tracker):
    """Wrap every call of the tracker's arithmetic (:func:`floor.arithmetic`: the methods of its
    components' contracts, FFTs, patch sampler, the loops' numerics); nested stages (features
    inside the scale estimator) are counted in both."""
    for owner, name, stage in arithmetic(tracker):
        setattr(owner, name, timed(stage, getattr(owner, name)))


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--config", default="dr2track")
    parser.add_argument("--root", default=str(Path(__file__).resolve().parents[2] / "shared/data/UAV123_10fps"))
    parser.add_argument("--sequence", default="boat1")
    parser.add_argument("--frames", type=int, default=100)
    parser.add_argument("--synthetic", action="store_true", help="synthetic 1280x720 frames even if the data exists")
    parser.add_argument("--json")
    args = parser.parse_args()
    if Path(args.root).is_dir() and not args.synthetic:
        from dcfkit.datasets import load_dataset

        (seq,) = load_dataset("uav123_10fps", args.root, [args.sequence])
        n = min(args.frames, len(seq))
        frames, box = [seq.frame(i) for i in range(n)], seq.init_box
    else:
        syn = make_sequence(n_frames=args.frames, size=(720, 1280), target=(40, 70))
        frames, box = syn.frames, syn.ground_truth[0]
        args.sequence = "synthetic_720p"
    tracker = dcfkit.load_tracker(args.config)
    instrument(tracker)
    TOTALS.clear()  # the stages of the updates only: init is cleared at the first update
    run = track(tracker, frames, box, lambda index, *_: TOTALS.clear() if index == 0 else None)
    total = float(run.times[1:].sum())
    n = len(frames) - 1
    print(f"{args.config} on {args.sequence}: {n / total:.1f} fps, {1000 * total / n:.2f} ms/frame")
    rows = sorted(TOTALS.items(), key=lambda kv: -kv[1])
    for stage, seconds in rows:
        print(f"  {stage:<40} {1000 * seconds / n:7.2f} ms  {100 * seconds / total:5.1f} %")
    if args.json:
        Path(args.json).write_text(json.dumps({"fps": n / total, "ms_per_frame": {k: 1000 * v / n for k, v in rows}},
                                              indent=2))


if __name__ == "__main__":
    main()
