"""What a run plan shows as it runs (:meth:`dcfkit.running.plan.RunPlan.execute`): nothing
(:class:`Progress`, ``search``), a bar in frames (``eval``) or a bar in runs (``ablate``).
Bars are tqdm's, drawn on a terminal only: a log file or a pipe gets no redrawn lines."""
from __future__ import annotations

import logging
from typing import Callable

log = logging.getLogger(__name__)


class Progress:
    """No bar: each hook does nothing. ``start(tasks, total)`` is called before the first run with
    the runs to track and the plan's distinct runs, ``frame()`` after each frame tracked in this
    process, ``result(shared, result)`` as each run ends (``shared``: a
    :class:`~dcfkit.running.plan.Shared`), ``close()`` at the end, whatever happened: it closes
    the ``bar`` a subclass's ``start`` made."""

    bar = None

    def start(self, tasks: list, total: int) -> None:
        pass

    def frame(self) -> None:
        pass

    def result(self, shared, result: dict) -> None:
        pass

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


def _bar(show: bool, tasks: list, **options):
    from tqdm.auto import tqdm  # lazy: tqdm.auto probes for Jupyter on import

    # disable=None: on a terminal only
    return tqdm(disable=None if show and tasks else True, dynamic_ncols=True, **options)


class FrameBar(Progress):
    """``eval``'s bar: the frames of the runs to track, named ``desc``; a failed run's message is
    logged as a warning."""

    def __init__(self, desc: str, show: bool = True):
        self.desc, self.show, self.frames = desc, show, 0

    def start(self, tasks: list, total: int) -> None:
        self.bar = _bar(self.show, tasks, total=sum(len(t.seq) for t in tasks), unit="frame", desc=self.desc)

    def frame(self) -> None:
        self.bar.update(1)

    def result(self, shared, result: dict) -> None:
        if result["status"] != "done":
            log.warning("%s: %s", self.desc, result["error"])
        self.frames += len(shared.task.seq)
        self.bar.set_postfix_str(shared.task.seq.name, refresh=False)
        self.bar.update(max(0, self.frames - self.bar.n))  # a failed run skips its rest; runs in lockstep end together


class RunBar(Progress):
    """``ablate``'s bar: the plan's distinct runs, those done before counted at the start, named
    ``desc``; ``label(shared)`` names a run's entries in its postfix (the first) and in the
    ``FAILED`` line written above the bar."""

    def __init__(self, desc: str, show: bool, label: Callable[[object], list[str]]):
        self.desc, self.show, self.label = desc, show, label

    def start(self, tasks: list, total: int) -> None:
        self.bar = _bar(self.show, tasks, total=total, initial=total - len(tasks), unit="job", desc=self.desc)

    def result(self, shared, result: dict) -> None:
        names = self.label(shared)
        if result["status"] != "done":
            self.bar.write(f"FAILED {', '.join(names)}: {result['error']}")
        self.bar.set_postfix_str(f"{names[0]} / {shared.task.seq.name}", refresh=False)
        self.bar.update(1)
