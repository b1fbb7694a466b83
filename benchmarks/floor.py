"""How close each tracker runs to its own arithmetic: the floor of a frame, and fps as a fraction.

    python benchmarks/floor.py [--configs strcf,bacf,dr2track] [--root ../shared/data/UAV123_10fps]
        [--frames 60] [--probe 10] [--repeats 5] [--json floor.json]

The *floor* of a frame is the time of its arithmetic alone: every call the tracker makes to
its components (features, label, solver, scale estimator, mask, search, ... through their
kinds' contracts), to its FFTs and to its patch sampler, recorded with its arguments on
``--probe`` frames near the end of a ``--frames`` run and replayed ``--repeats`` times each,
warm, after the run; the fastest replay counts, and calls made inside another recorded call
count once, in the outer one. What the floor leaves out is the tracker's own glue (Python
between the calls, allocation, caches lost between stages). The tracker's fps is measured
on the same frames in a separate, unrecorded run, so that copying the arguments costs it
nothing. Prints, per config and sequence, fps, the floor's fps and their ratio (fps / floor
fps: 1 would be a frame that costs no more than its parts), and the median ratio.

Single-threaded; frames are decoded before timing. The UAV123@10fps development sequences
and a synthetic 1280x720 sequence (only that when the data is absent).
"""
import os

for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[var] = "1"

import argparse  # noqa: E402
import functools  # noqa: E402
import inspect  # noqa: E402
import json  # noqa: E402
import statistics  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import cv2  # noqa: E402
import numpy as np  # noqa: E402

import dcfkit  # noqa: E402
import dcfkit.tracker.continuous as continuous_module  # noqa: E402
import dcfkit.tracker.tracker as tracker_module  # noqa: E402
from dcfkit.components.base import Component  # noqa: E402
from dcfkit.datasets.synthetic import make_sequence  # noqa: E402
from dcfkit.numerics import fourier_series  # noqa: E402

cv2.setNumThreads(1)
ARITHMETIC = ("dcfkit.numerics", "dcfkit.components.solvers", "dcfkit.components.features", "dcfkit.tracker.blocks",
              "dcfkit.tracker.learnt")


class Recorder:
    """Wraps a tracker's arithmetic; while ``on``, keeps each outermost call with a copy of its
    arrays (copied before the call: a call may change its inputs in place)."""

    def __init__(self):
        self.on, self.depth, self.calls, self.wrapped = False, 0, [], []

    def wrap(self, owner, name: str, stage: str) -> None:
        fn = getattr(owner, name)
        self.wrapped.append((owner, name, fn))

        @functools.wraps(fn)
        def recorded(*args, **kwargs):
            keep = self.on and self.depth == 0
            saved = (stage, fn, snapshot(args), snapshot(kwargs)) if keep else None
            self.depth += 1
            try:
                return fn(*args, **kwargs)
            finally:
                self.depth -= 1
                if saved is not None:
                    self.calls.append(saved)

        setattr(owner, name, recorded)

    def instrument(self, tracker) -> None:
        """Every call :func:`arithmetic` names."""
        for owner, name, stage in arithmetic(tracker):
            self.wrap(owner, name, stage)

    def restore(self) -> None:
        """The module functions as they were (the next tracker gets its own recorder)."""
        for owner, name, fn in reversed(self.wrapped):
            setattr(owner, name, fn)
        self.wrapped.clear()

    def replay(self, repeats: int) -> dict[str, float]:
        """Seconds per stage, each call at its fastest of ``repeats`` warm replays."""
        self.on = False  # the calls a replayed call makes are its own, not new records
        stages: dict[str, float] = {}
        for stage, fn, args, kwargs in self.calls:
            best = float("inf")
            for _ in range(repeats):
                a, k = snapshot(args), snapshot(kwargs)
                start = time.perf_counter()
                fn(*a, **k)
                best = min(best, time.perf_counter() - start)
            stages[stage] = stages.get(stage, 0.0) + best
        return stages


def snapshot(value):
    """``value`` with its arrays copied (inside lists, tuples and dicts); other objects (the
    tracker's state, a backend) are passed as they are."""
    if isinstance(value, np.ndarray):
        return value.copy()
    if isinstance(value, (list, tuple)):
        return type(value)(snapshot(v) for v in value) if type(value) in (list, tuple) else value
    if isinstance(value, dict):
        return {k: snapshot(v) for k, v in value.items()}
    return value


def arithmetic(tracker) -> list[tuple]:
    """``(owner, name, stage)`` of each call that is the tracker's arithmetic: every component
    method its kind's contract names (but those of frame 1), the FFTs, the patch sampler, and the
    numerics the loops import (peaks, ECO's projection, Fourier series and feature blocks) by
    the names the loops call them."""
    t = tracker.loop.t if getattr(tracker, "loop", None) is not None else tracker
    found = []
    for component in components(t):
        contract = type(component).contract
        for name in (*contract.required, *contract.optional):
            if name not in ("reset", "start", "init"):  # frame 1 only
                found.append((component, name, f"{component.kind} {component.name}.{name}"))
    fft = getattr(t, "fft", None)
    for name in ("rfft2", "irfft2", "fft2", "ifft2"):
        if fft is not None and callable(getattr(fft, name, None)):
            found.append((fft, name, "fft"))
    if callable(getattr(t, "_patch", None)):
        found.append((t, "_patch", "patch extraction"))
    for module in (tracker_module, continuous_module, fourier_series):
        for name, fn in list(vars(module).items()):
            if inspect.isfunction(fn) and fn.__module__.startswith(ARITHMETIC) and not name.startswith("_"):
                found.append((module, name, name))
    return found


def components(tracker) -> list:
    """The tracker's components, each once (features are a list)."""
    found = []
    for value in vars(tracker).values():
        for item in value if isinstance(value, (list, tuple)) else (value,):
            if isinstance(item, Component) and all(item is not f for f in found):
                found.append(item)
    return found


def run(config: str, frames: list, box, probe: int, recorder: Recorder | None = None) -> float:
    """Seconds per frame over the last ``probe`` frames (recorded by ``recorder`` if given)."""
    tracker = dcfkit.load_tracker(config)
    if recorder is not None:
        recorder.instrument(tracker)
    tracker.init(frames[0], box)
    first = len(frames) - probe
    for frame in frames[1:first]:
        tracker.update(frame)
    if recorder is not None:
        recorder.on = True
    start = time.perf_counter()
    for frame in frames[first:]:
        tracker.update(frame)
    elapsed = time.perf_counter() - start
    if recorder is not None:
        recorder.on = False
        recorder.restore()
    return elapsed / probe


def sequences(root: Path, n: int) -> list:
    """(name, first ``n`` decoded frames, initial box) per development sequence, and 720p."""
    found = []
    if root.is_dir():
        from dcfkit.datasets import load_dataset  # the data may be absent

        for seq in load_dataset("uav123_10fps", root):
            found.append((seq.name, [seq.frame(i) for i in range(min(n, len(seq)))], seq.init_box))
    syn = make_sequence(n_frames=n, size=(720, 1280), target=(40, 70))
    return found + [("synthetic_720p", syn.frames, syn.ground_truth[0])]


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--configs", default="kcf,dsst,strcf,bacf,arcf,autotrack,dr2track,eco_hc,csrdcf")
    parser.add_argument("--root", default=str(Path(__file__).resolve().parents[2] / "shared/data/UAV123_10fps"))
    parser.add_argument("--frames", type=int, default=60)
    parser.add_argument("--probe", type=int, default=10)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--json")
    args = parser.parse_args()
    rows = []
    for name, frames, box in sequences(Path(args.root), args.frames):
        probe = min(args.probe, len(frames) - 2)
        for config in args.configs.split(","):
            per_frame = run(config, frames, box, probe)
            recorder = Recorder()
            run(config, frames, box, probe, recorder)
            stages = {k: v / probe for k, v in recorder.replay(args.repeats).items()}
            floor = sum(stages.values())
            rows.append({"sequence": name, "config": config, "fps": 1 / per_frame, "floor_fps": 1 / floor,
                         "ratio": floor / per_frame, "floor_ms": {k: 1000 * v for k, v in stages.items()}})
            print(f"{name:<14} {config:<12} {1 / per_frame:7.1f} fps  floor {1 / floor:7.1f} fps  "
                  f"x{floor / per_frame:.2f} of it", flush=True)
    print("\nmedian over the real sequences (720p apart):")
    medians = {}
    for config in args.configs.split(","):
        real = [r for r in rows if r["config"] == config and r["sequence"] != "synthetic_720p"] or \
            [r for r in rows if r["config"] == config]
        hd = [r for r in rows if r["config"] == config and r["sequence"] == "synthetic_720p"]
        medians[config] = {k: statistics.median(r[k] for r in real) for k in ("fps", "floor_fps", "ratio")}
        m = medians[config]
        hd_text = f"   720p {hd[0]['fps']:.1f} fps, floor {hd[0]['floor_fps']:.1f}, x{hd[0]['ratio']:.2f}" if hd else ""
        print(f"  {config:<12} {m['fps']:7.1f} fps  floor {m['floor_fps']:7.1f} fps  x{m['ratio']:.2f}{hd_text}")
    if args.json:
        Path(args.json).write_text(json.dumps({"rows": rows, "median": medians}, indent=1))


if __name__ == "__main__":
    main()
