"""Tracker speed on real or synthetic frames: fps per config, image decoding excluded.

    python benchmarks/speed.py [--root ../shared/data/UAV123_10fps] [--configs strcf,bacf,dr2track]
        [--passes 3] [--json speed.json]

A config may be a shipped name, a YAML path, or ``opencv:CSRT`` (``opencv:KCF``, ``opencv:MOSSE``):
OpenCV's tracker timed the same way in the same run, as a yardstick.

Run single-threaded (the script sets OMP/OPENBLAS/MKL threads to 1 before numpy loads).
Frames are decoded one at a time outside the timer; only init/update are timed. Runs the
UAV123@10fps sequences and a synthetic sequence of the same 1280x720 frame size. Prints
per-sequence fps, the median over the real sequences per config, the process's peak RSS, and
the first frame's cost in a fresh process (imports, numba's cached code, the CN table).
"""
import os

for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[var] = "1"

import argparse  # noqa: E402
import json  # noqa: E402
import resource  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
from pathlib import Path  # noqa: E402

import cv2  # noqa: E402
import numpy as np  # noqa: E402

import dcfkit  # noqa: E402
from dcfkit.datasets.synthetic import make_sequence  # noqa: E402
from dcfkit.experiments.loop import track as run_track  # noqa: E402
from dcfkit.integrations.opencv import opencv_tracker  # noqa: E402

cv2.setNumThreads(1)
SYNTHETIC = "synthetic_720p"


def sequences(root):
    """(name, frame getter, number of frames, initial box) per real sequence; frames are
    decoded one at a time, so the peak RSS is the trackers' plus one frame's."""
    if root and Path(root).is_dir():
        from dcfkit.datasets import load_dataset

        for seq in load_dataset("uav123_10fps", root):
            yield seq.name, seq.frame, len(seq), seq.init_box
    else:
        print(f"no real data at {root!r}: synthetic frames only")


def synthetic(n_frames: int):
    """A generated sequence of UAV123's frame size (its frames are all held in memory)."""
    seq = make_sequence(n_frames=n_frames, size=(720, 1280), target=(40, 70))
    yield SYNTHETIC, seq.frames.__getitem__, len(seq.frames), seq.ground_truth[0]


FRESH_PROCESS = """
import sys, time
import cv2, numpy
cv2.setNumThreads(1)
# synthetic: noise, not one grey, which the tracker refuses as a blank frame
frame = cv2.imread(sys.argv[2]) if sys.argv[2] else numpy.random.default_rng(0).integers(0, 256, (720, 1280, 3), numpy.uint8)
box = [float(v) for v in sys.argv[3].split(",")]
start = time.perf_counter()
import dcfkit
if sys.argv[1].lower().startswith("opencv:"):
    from dcfkit.integrations.opencv import opencv_tracker
    tracker = opencv_tracker(sys.argv[1].partition(":")[2])()
else:
    tracker = dcfkit.load_tracker(sys.argv[1])
loaded = time.perf_counter()
tracker.init(frame, box)
tracker.update(frame)
print(loaded - start, time.perf_counter() - loaded)
"""


def first_frame_fresh(config: str, image: str, box) -> tuple[float, float]:
    """(import + load_tracker, init + first update) seconds in a new Python process: everything
    a first frame costs (numba loading its cached machine code, the CN table) but decoding."""
    out = subprocess.run([sys.executable, "-c", FRESH_PROCESS, config, image, ",".join(map(str, box))],
                         check=True, capture_output=True, text=True).stdout.split()
    return float(out[0]), float(out[1])


def make_tracker(config: str):
    """A dcfkit tracker, or OpenCV's for ``opencv:NAME``."""
    if config.lower().startswith("opencv:"):
        return opencv_tracker(config.partition(":")[2])()
    return dcfkit.load_tracker(config)


def track(config: str, frame_at, n_frames: int, box) -> tuple[float, float]:
    """(fps of update over frames 2..n, seconds of init), decoding excluded."""
    times = run_track(make_tracker(config), (frame_at(i) for i in range(n_frames)), box).times
    return (n_frames - 1) / float(times[1:].sum()), float(times[0])


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--root", default=str(Path(__file__).resolve().parents[2] / "shared/data/UAV123_10fps"))
    parser.add_argument("--configs", default="strcf,bacf,dr2track")
    parser.add_argument("--passes", type=int, default=1,
                        help="sweeps over all sequences; each run's best fps counts (a shared machine slows "
                             "down for minutes at a time, so passes minutes apart filter that out)")
    parser.add_argument("--json", help="also write the table here")
    parser.add_argument("--synthetic-frames", type=int, default=200, help="frames of the synthetic sequence")
    args = parser.parse_args()
    configs = args.configs.split(",")
    rows = []
    rss = None

    def all_sequences():
        nonlocal rss
        yield from sequences(args.root)
        if rows:  # before the synthetic frames, which are all held in memory
            rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
        yield from synthetic(args.synthetic_frames)

    sweeps = [all_sequences()] + [sequences(args.root) for _ in range(args.passes - 1)]
    for sweep, runs in enumerate(sweeps):
        for name, frame_at, n_frames, box, config in ((*r, c) for r in runs for c in configs):
            fps, first = track(config, frame_at, n_frames, box)
            rows.append({"sequence": name, "config": config, "pass": sweep + 1, "fps": fps, "first_frame_s": first})
            print(f"{name:<14} {config:<10} {fps:7.1f} fps   first frame {first * 1000:6.1f} ms   pass {sweep + 1}",
                  flush=True)
    print(f"\nmedian over the real sequences (synthetic only when there are none), best of {args.passes} pass(es):")
    summary = {}
    best = {}
    for r in rows:  # best pass per (sequence, config)
        key = (r["sequence"], r["config"])
        best[key] = max(best.get(key, 0.0), r["fps"])
    for config in configs:
        real = [v for (seq, c), v in best.items() if c == config and seq != SYNTHETIC]
        summary[config] = float(np.median(real or [v for (seq, c), v in best.items() if c == config]))
        print(f"  {config:<10} {summary[config]:7.1f} fps")
    if rss is None:
        rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"peak RSS {rss:.0f} MB (all trackers, one frame at a time)")

    first = {}
    image, box = "", (600, 320, 70, 40)
    if Path(args.root).is_dir():
        from dcfkit.datasets import load_dataset

        seq = load_dataset("uav123_10fps", args.root)[0]
        image, box = str(seq.frames[0]), seq.init_box
    print("\nfirst frame in a fresh process (median of 3; decoding excluded):")
    for config in configs:
        runs = sorted((first_frame_fresh(config, image, box) for _ in range(3)), key=sum)
        imports, init = runs[1]
        first[config] = {"import_and_load_s": imports, "init_and_first_update_s": init}
        print(f"  {config:<10} import + load_tracker {imports:5.2f} s, init + first update {init:5.2f} s, "
              f"total {imports + init:5.2f} s")
    if args.json:
        Path(args.json).write_text(json.dumps({"rows": rows, "median_fps": summary, "peak_rss_mb": rss,
                                               "first_frame_fresh_process": first}, indent=2))


if __name__ == "__main__":
    main()
