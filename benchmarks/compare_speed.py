"""Speed of this checkout against another one, interleaved, as ratios.

    git worktree add /tmp/base <commit>
    python benchmarks/compare_speed.py /tmp/base [--configs strcf,bacf,dr2track] [--repeats 2]

A shared machine's speed drifts by tens of percent within minutes, so two benchmark runs
minutes apart do not compare. Here every (sequence, config) runs in both checkouts back to
back, in fresh single-threaded processes, alternating which goes first; the ratio of the
two fps is what is reported (per run, and the median over sequences per config).
Image decoding is excluded from the timing, as in ``speed.py``.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parents[1]
# The loop is written out, not dcfkit.experiments.loop.track: the other checkout may predate it.
RUN = """
import os, sys, time
import cv2
cv2.setNumThreads(1)
import dcfkit
from dcfkit.datasets import load_dataset
(seq,) = load_dataset("uav123_10fps", sys.argv[1], [sys.argv[2]])
frames = [seq.frame(i) for i in range(len(seq))]
tracker = dcfkit.load_tracker(sys.argv[3])
tracker.init(frames[0], seq.init_box)
start = time.perf_counter()
for frame in frames[1:]:
    tracker.update(frame)
print(dcfkit.__file__, (len(frames) - 1) / (time.perf_counter() - start))
"""


def fps(checkout: Path, root: str, sequence: str, config: str) -> float:
    env = dict(os.environ, PYTHONPATH=str(checkout), OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1",
               MKL_NUM_THREADS="1")
    # run in the checkout: `python -c` puts the working folder first on sys.path
    out = subprocess.run([sys.executable, "-c", RUN, root, sequence, config], env=env, check=True,
                         capture_output=True, text=True, cwd=checkout)
    module, value = out.stdout.split()[-2:]
    if not Path(module).resolve().is_relative_to(checkout.resolve()):
        raise SystemExit(f"{checkout}: the run imported dcfkit from {module}, not from the checkout")
    return float(value)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("baseline", type=Path, help="another dcfkit checkout (its top folder)")
    parser.add_argument("--root", default=str(HERE.parent / "shared/data/UAV123_10fps"))
    parser.add_argument("--configs", default="strcf,bacf,dr2track")
    parser.add_argument("--repeats", type=int, default=1, help="runs per (sequence, config) and checkout")
    parser.add_argument("--json")
    args = parser.parse_args()
    if not (args.baseline / "dcfkit").is_dir():
        parser.error(f"{args.baseline} is not a dcfkit checkout (no dcfkit/ folder in it)")
    if not Path(args.root).is_dir():
        parser.error(f"no UAV123@10fps data at {args.root}; pass --root")
    sys.path.insert(0, str(HERE))
    from dcfkit.datasets import load_dataset

    names = [s.name for s in load_dataset("uav123_10fps", args.root)]
    rows = []
    for k in range(args.repeats):
        for name in names:
            for config in args.configs.split(","):
                order = [("baseline", args.baseline), ("this", HERE)]
                if k % 2:
                    order.reverse()
                measured = {label: fps(path, args.root, name, config) for label, path in order}
                ratio = measured["this"] / measured["baseline"]
                rows.append({"sequence": name, "config": config, **measured, "ratio": ratio})
                print(f"{name:<14} {config:<10} baseline {measured['baseline']:6.1f} fps   this "
                      f"{measured['this']:6.1f} fps   x{ratio:.2f}", flush=True)
    print("\nmedian over sequences (fps baseline -> this, median ratio):")
    summary = {}
    for config in args.configs.split(","):
        mine = [r for r in rows if r["config"] == config]
        summary[config] = {key: statistics.median(r[key] for r in mine) for key in ("baseline", "this", "ratio")}
        s = summary[config]
        print(f"  {config:<10} {s['baseline']:6.1f} -> {s['this']:6.1f} fps   x{s['ratio']:.2f}")
    if args.json:
        Path(args.json).write_text(json.dumps({"rows": rows, "median": summary}, indent=2))


if __name__ == "__main__":
    main()
