"""Runs that share their frames, tracked in lockstep: each frame decoded once for all of them.

TRE's runs of a sequence start at up to 20 of its frames and all end at its last; SRE's twelve
all cover it whole. Tracked one after another, each run decodes its frames again: about ten
decodes a frame under TRE, twelve under SRE, where one decode of a 720p JPEG costs a third of a
DCF tracker's update (docs/results.md, "Reading frames"). A *group* is the runs of one config
whose frames are the tail of one run's (the longest); :func:`run_group` decodes those frames
:data:`BLOCK` at a time and runs each tracker through the block in turn (whose data then stays
in the CPU's caches, where stepping them frame by frame lost most of the gain for CSR-DCF),
handing each run its own copy of each frame it has (a tracker may write into its image), and
stores each run as
:func:`~dcfkit.running.runner.run_sequence` does: the same boxes, a failure failing only its
run. Only runs that their experiment tracks plainly from the first box are grouped (its
:meth:`~dcfkit.experiments.base.Experiment.track` not overridden, as VOT's restarts override it).

A run in a group is timed with the other trackers' work between its frames, sharing the CPU's
caches: its sidecar's ``timing`` says ``alone: false`` and ``lockstep``, the group's size
(:mod:`dcfkit.store.timing`)."""
from __future__ import annotations

import dataclasses
from typing import Callable, Iterable, Iterator, Mapping

import numpy as np

from dcfkit.experiments import Experiment
from dcfkit.experiments.loop import Track, TrackerFailure, steps
from dcfkit.running import runner
from dcfkit.running.runner import RunTask
from dcfkit.store.timing import timing_record


def groups(tasks: Iterable[RunTask], parts: int = 1) -> list[list[RunTask]]:
    """``tasks`` as units to run: groups of runs sharing their frames (each longest run first)
    and single runs, the most frames first. With ``parts`` > 1 (workers), a group holding more
    than half a worker's share of the frames is split into interleaved halves, so that the
    workers end together."""
    units, candidates = [], {}
    for task in tasks:
        if task.alone or type(task.experiment).track is not Experiment.track:
            units.append([task])
            continue
        key = (task.key, str(task.folder), id(task.make_tracker), task.experiment.name, str(task.seq.frames[-1]))
        candidates.setdefault(key, []).append(task)
    for found in candidates.values():
        found.sort(key=lambda t: -len(t.seq))
        parent = found[0].seq
        tail = [parent.frames[len(parent) - len(t.seq):] == t.seq.frames for t in found]
        units += [[t for t, inside in zip(found, tail) if inside]] + [[t] for t, inside in zip(found, tail)
                                                                        if not inside]
    if parts > 1:
        share = sum(_frames(u) for u in units) / (2 * parts)
        while units and len(big := max(units, key=lambda u: _frames(u) if len(u) > 1 else 0)) > 1 \
                and _frames(big) > share:
            units = [u for u in units if u is not big] + [big[0::2], big[1::2]]  # each half: its longest first
    return sorted(units, key=lambda u: -_frames(u))


def _frames(unit: list[RunTask]) -> int:
    return sum(len(t.seq) for t in unit)


BLOCK = 16  # frames decoded at a time; each tracker then runs through them in turn, its data kept in the caches


@dataclasses.dataclass
class _Run:
    """A run being tracked: its :func:`~dcfkit.experiments.loop.steps`, the frame handed to it next, what it gave."""

    steps: Iterator
    handed: list
    boxes: list = dataclasses.field(default_factory=list)
    times: list = dataclasses.field(default_factory=list)
    confidence: list = dataclasses.field(default_factory=list)

    def track(self) -> Track:
        return Track.collected(self.boxes, self.times, self.confidence)


def run_group(tasks: list[RunTask], version: str, on_frame: Callable[[], None] | None = None,
              origin: Mapping | None = None, timing: Mapping | None = None) -> list[dict]:
    """Each of ``tasks`` (a unit of :func:`groups`) run and stored, the longest run's frames
    decoded once, :data:`BLOCK` at a time, and handed to every run that has them; returns the
    runs' summaries in order (:func:`~dcfkit.running.runner.run_sequence`'s). ``on_frame()``
    after each run's frame."""
    if len(tasks) == 1:
        return [runner.run_sequence(tasks[0], version, on_frame, origin, timing)]
    runner._warm_up(tasks[0])
    timing = {**(timing or timing_record("local", 1)), "alone": False, "lockstep": len(tasks)}
    parent = tasks[0].seq
    offsets = [len(parent) - len(t.seq) for t in tasks]
    results: list[dict | None] = [None] * len(tasks)
    active: dict[int, _Run] = {}
    for first in range(min(offsets), len(parent), BLOCK):
        block = range(first, min(first + BLOCK, len(parent)))
        for k in (k for k, offset in enumerate(offsets) if offset in block):
            try:
                handed: list = [None]
                active[k] = _Run(steps(runner.make_tracker(tasks[k]), _handed(handed), tasks[k].seq.init_box),
                                 handed)
            except Exception as exc:
                message = runner.failure_message(tasks[k].seq, exc, True, None)
                results[k] = runner.record_failure(tasks[k], version, message, exc)
        if not active:  # none running: decode nothing until the next run starts, if any does
            if max(offsets) < block.stop:
                break
            continue
        lowest = min(offsets[k] for k in active)
        frames = {i: _read(parent, i) for i in block if i >= lowest}
        last = {i: max(k for k in active if offsets[k] <= i) for i in frames}  # handed the frame, not a copy
        for k in list(active):
            for i in block[max(0, offsets[k] - first):]:
                j = i - offsets[k]  # the run's own frame
                try:
                    frame = frames[i]
                    active[k].handed[0] = tasks[k].seq.frame(j) if frame is None else frame if k == last[i] else \
                        frame.copy()
                    step = next(active[k].steps)
                except Exception as exc:
                    failed = exc.frame if isinstance(exc, TrackerFailure) else j + 1
                    message = runner.failure_message(tasks[k].seq, exc, False, failed)
                    results[k] = runner.record_failure(tasks[k], version, message, exc, failed)
                    del active[k]
                    break
                active[k].boxes.append(step.box)
                active[k].times.append(step.seconds)
                active[k].confidence.append(step.confidence)
                if on_frame is not None:
                    on_frame()
    for k, run in active.items():
        run.steps.close()
        results[k] = runner.store_run(tasks[k], run.track(), version, origin, timing)
    return results


def _handed(handed: list):
    """The frames a run's :func:`~dcfkit.experiments.loop.steps` reads: each the one handed to it."""
    while True:
        yield handed[0]


def _read(parent, i: int) -> np.ndarray | None:
    """Frame ``i`` of the longest run, or None if it cannot be read: each run then reads its own,
    so that its failure names its frame as a run of its own would."""
    try:
        return parent.frame(i)
    except Exception:
        return None
