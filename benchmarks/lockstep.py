"""What tracking a sequence's TRE (or SRE) runs in lockstep saves, and that it changes no box.

    python benchmarks/lockstep.py ../shared/data/UAV123_10fps --configs kcf,dr2track --sequences boat1,car7

For each config and sequence, the experiment's runs are tracked and stored twice in this one
process, one thread, alternating which comes first: one by one, as
:func:`dcfkit.running.runner.run_sequence` runs each (every run decoding its own frames), and
together (:func:`dcfkit.running.lockstep.run_group`: each frame decoded once). Prints the wall
seconds of each (decoding, tracking and storing), their ratio, and whether every boxes and
confidence file is the same; exits with 1 if any differs. ``--repeats N`` takes each way's
fastest of N.
"""
import argparse
import sys
import tempfile
import time
from pathlib import Path

import cv2

from dcfkit import load_config
from dcfkit.datasets import load_dataset
from dcfkit.experiments import EXPERIMENTS
from dcfkit.running import lockstep
from dcfkit.running.runner import RunTask, run_sequence
from dcfkit.store.provenance import dcfkit_version, run_key


def tasks(config: dict, seq, experiment, folder: Path) -> list[RunTask]:
    folder.mkdir(parents=True, exist_ok=True)
    key = run_key(config, dcfkit_version(), experiment.rule)
    return [RunTask(config, run, folder, key, None, experiment) for run in experiment.runs(seq)]


def timed_ways(config: dict, seq, experiment, scratch: Path, repeats: int) -> tuple[float, float, bool]:
    """Seconds one by one and together (each the fastest of ``repeats``), and whether they stored the same."""
    seconds = {"alone": [], "together": []}
    version = dcfkit_version()
    for repeat in range(repeats):
        ways = ("alone", "together") if repeat % 2 == 0 else ("together", "alone")
        for way in ways:
            units = tasks(config, seq, experiment, scratch / way / str(repeat))
            start = time.perf_counter()
            if way == "alone":
                for task in units:
                    run_sequence(task, version)
            else:
                for unit in lockstep.groups(units):
                    lockstep.run_group(unit, version)
            seconds[way].append(time.perf_counter() - start)
    same = all(_stored(scratch / "alone" / str(r)) == _stored(scratch / "together" / str(r)) for r in range(repeats))
    return min(seconds["alone"]), min(seconds["together"]), same


def _stored(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in folder.iterdir() if p.suffix in (".txt", ".confidence")}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("root", help="a benchmark root (its layout detected)")
    parser.add_argument("--configs", default="kcf,dr2track", help="comma-separated configs (default kcf,dr2track)")
    parser.add_argument("--sequences", default=None, help="comma-separated sequence names (default: all)")
    parser.add_argument("--experiment", choices=("tre", "sre"), default="tre")
    parser.add_argument("--repeats", type=int, default=1)
    args = parser.parse_args()
    cv2.setNumThreads(1)
    experiment = EXPERIMENTS[args.experiment]
    print(f"{'config':<12} {'sequence':<16} {'runs':>5} {'one by one s':>13} {'lockstep s':>11} {'ratio':>6} same")
    differ = []
    with tempfile.TemporaryDirectory() as scratch:
        for name in args.configs.split(","):
            config = load_config(name)
            for seq in load_dataset(None, args.root, args.sequences):
                alone, together, same = timed_ways(config, seq, experiment, Path(scratch) / name / seq.name,
                                                   args.repeats)
                print(f"{name:<12} {seq.name:<16} {len(experiment.runs(seq)):>5} {alone:>13.2f} {together:>11.2f} "
                      f"{alone / together:>6.2f} {'yes' if same else 'NO'}", flush=True)
                if not same:
                    differ.append(f"{name} on {seq.name}")
    if differ:
        print("stored results differ: " + ", ".join(differ))
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
