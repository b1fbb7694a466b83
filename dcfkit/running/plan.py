"""One run plan for every command that makes runs (``eval``, ``ablate``, ``search``): entries
(a folder name, a resolved config, a tracker factory) on sequences in one experiment, each
entry's runs stored in ``OUT/<name>/[<experiment>/]`` (:mod:`dcfkit.running.layout`).

A plan knows each entry's run key, its runs and which are done or to do. Before anything is
tracked it checks what ``eval`` always checked (:mod:`dcfkit.running.checks`: the first boxes
when the experiment starts from them, one benchmark per folder, no intact run replaced by one
of fewer frames, each folder writable), claims the runs it writes (:mod:`dcfkit.store.claims`)
and says what it recomputes and why. Each distinct run (run key, tracker factory, run) is
tracked once, by :func:`dcfkit.running.execute.execute`; the other entries of its key get its
files (:meth:`~dcfkit.store.results.ResultStore.copy_run`), as does an entry lacking a run
another entry of its key holds done, or a run the entry has done in another experiment (OPE's
run is TRE's first when that starts at frame 1). A consumer makes a plan, calls
:meth:`RunPlan.run` and reports (docs/architecture.md, "Where to add")."""
from __future__ import annotations

import dataclasses
import logging
from typing import Callable, Iterable, Mapping

from dcfkit.datasets import DatasetError, Sequence
from dcfkit.errors import DcfkitError, shown
from dcfkit.experiments import EXPERIMENTS, Experiment, get_experiment, run_identity, runs_by_sequence
from dcfkit.running.checks import check_first_boxes, check_same_dataset, say_other_rule, say_what_is_recomputed
from dcfkit.running.layout import store_folder
from dcfkit.running.progress import Progress
from dcfkit.running.execute import execute
from dcfkit.running.runner import RunTask, warm_up_compiled
from dcfkit.store import provenance
from dcfkit.store.claims import claimed_folders
from dcfkit.store.files import StoreError, ensure_writable, make_dir, remove_temporary_files
from dcfkit.store.results import ResultStore

log = logging.getLogger(__name__)


@dataclasses.dataclass(frozen=True)
class Entry:
    """What a command asks to run: ``config`` (resolved) stored under ``OUT/<name>/``, each
    tracker made by ``make_tracker(config)`` (None: :func:`dcfkit.load_tracker`)."""

    name: str
    config: Mapping
    make_tracker: Callable | None = None


@dataclasses.dataclass(eq=False)
class Planned:
    """An entry in a plan: its store, run key and runs; ``metas`` (each run's sidecar) and
    ``todo`` once read; ``done`` (made now: tracked, or copied from another entry of its key)
    and ``failed`` (run -> message) once run."""

    entry: Entry
    store: ResultStore
    key: str
    runs: list[Sequence]
    metas: dict = dataclasses.field(default_factory=dict)
    todo: list[Sequence] = dataclasses.field(default_factory=list)
    done: list[str] = dataclasses.field(default_factory=list)
    failed: dict[str, str] = dataclasses.field(default_factory=dict)

    @property
    def name(self) -> str:
        return self.entry.name

    @property
    def skipped(self) -> list[str]:
        """The runs found done, in order."""
        todo = {run.name for run in self.todo}
        return [run.name for run in self.runs if run.name not in todo]

    def outcome(self) -> dict:
        """``{"tracker", "dir", "run_key", "done", "skipped", "failed"}``, runs in order (eval's summary)."""
        order = {run.name: i for i, run in enumerate(self.runs)}
        return {"tracker": self.name, "dir": self.store.folder, "run_key": self.key,
                "done": sorted(self.done, key=order.get), "skipped": self.skipped, "failed": dict(self.failed)}


@dataclasses.dataclass(eq=False)
class Shared:
    """One run to track, ``task``, into its first member's store; the other ``members`` (entries
    of its run key that lack it) get its files."""

    task: RunTask
    members: list[Planned]


class RunPlan:
    """The runs of ``entries`` on ``sequences`` in ``experiment`` (bound to its rule, if it has
    one) under ``out``. ``what`` names the results in errors (default ``<name>'s results``)."""

    def __init__(self, entries: Iterable[Entry], sequences: Iterable[Sequence], experiment: str | Experiment,
                 out, what: str | None = None, version: str | None = None):
        self.experiment, self.sequences, self.out = get_experiment(experiment), list(sequences), out
        self.version, self.what = version if version is not None else provenance.dcfkit_version(), what
        self.by_sequence = runs_by_sequence(self.sequences, self.experiment)
        self.one_pass_twins = {run.name for seq in self.sequences for run in self.by_sequence.get(seq.name, ())
                               if run_identity(run) == run_identity(seq)}  # OPE's run itself, TRE's first
        runs = [run for found in self.by_sequence.values() for run in found]
        self.entries = [Planned(e, ResultStore(store_folder(out, e.name, self.experiment)),
                                provenance.run_key(e.config, self.version, self.experiment.rule), runs) for e in entries]
        folders = [p.store.folder for p in self.entries]
        twice = sorted({str(f) for f in folders if folders.count(f) > 1})
        if twice:
            raise DcfkitError(f"two entries of a run plan would write to one folder: {shown(twice[0])}")
        self.tracked: list[tuple[Shared, dict]] = []

    def read(self) -> "RunPlan":
        """Read each entry's sidecars and find its runs to do (not done, or made under another
        of the experiment's rules); writes nothing."""
        for p in self.entries:
            p.metas = {run.name: p.store.sidecar(run.name) for run in p.runs}  # each read once
            p.todo = [run for run in p.runs if p.store.status(run, p.key, p.metas[run.name]) != "done"
                      or self.experiment.stored_elsewise(p.metas[run.name]) is not None]
        return self

    def check(self) -> "RunPlan":
        """:meth:`read`, then raise now what would stop the runs: a first box missing (when the
        experiment starts from it), another benchmark's results in a folder, an intact run of
        more frames (``--max-frames``), a folder (with runs to do) that cannot take the files."""
        if self.experiment.first_box:
            check_first_boxes(self.sequences)
        self.read()
        for p in self.entries:
            check_same_dataset(p.store, p.metas, p.todo)
            for run in p.todo:
                p.store.refuse_to_shorten(run, p.metas[run.name])
            if p.todo:
                ensure_writable(p.store.folder, [f for run in p.todo for f in p.store.file_names(run.name)],
                                self.what or f"{p.name}'s results")
        return self

    @property
    def distinct(self) -> int:
        """The distinct runs of the plan: one per run key, tracker factory and run."""
        return sum(len(members[0].runs) for members in self._groups())

    def _groups(self) -> list[list[Planned]]:
        """The entries grouped by run key and tracker factory (the same runs' files)."""
        groups: dict[tuple, list[Planned]] = {}
        for p in self.entries:
            groups.setdefault((p.key, id(p.entry.make_tracker)), []).append(p)
        return list(groups.values())

    def shared(self) -> tuple[list[Shared], list[tuple[Planned, list[Planned], str]]]:
        """(the runs to track, each once, with the entries that get it; the copies to make: a
        run done in one entry, the entries of its key lacking it, its name). A run an entry
        has made now (a copy from another experiment) counts as done in it."""
        tasks, copies = [], []
        for members in self._groups():
            todo = [{run.name for run in p.todo} - set(p.done) for p in members]
            for run in members[0].runs:
                lacking = [p for p, names in zip(members, todo) if run.name in names]
                having = [p for p, names in zip(members, todo) if run.name not in names]
                if lacking and having:
                    copies.append((having[0], lacking, run.name))
                elif lacking:
                    first = lacking[0]
                    tasks.append(Shared(RunTask(dict(first.entry.config), run, first.store.folder, first.key,
                                                first.entry.make_tracker, self.experiment,
                                                alone=run.name in self.one_pass_twins), lacking))
        return tasks, copies

    def run(self, command: str, jobs: int = 1, executor: str = "local", scheduler: str | None = None,
            progress: Progress | None = None) -> "RunPlan":
        """Claim every entry's runs for ``command``, :meth:`check` them, say what is recomputed
        and why, and :meth:`execute` the plan."""
        for p in self.entries:
            if not p.store.folder.is_dir():
                make_dir(p.store.folder)  # a first run: the locks need the folder
        kind = "run" if self.experiment.folder else "sequence"
        claims = {p.store.folder: ([run.name for run in p.runs], _claim_text(p, kind)) for p in self.entries}
        with claimed_folders(claims, command):  # other runs of these folders may go on alongside
            self.check()
            for p in self.entries:
                say_what_is_recomputed(p.store, p.metas, p.todo, p.entry.config, p.name, p.key)
                say_other_rule(p.store, p.metas, p.todo, self.experiment)
                # every run of the folder it claims: none is being written by another command
                remove_temporary_files(p.store.folder, [f for run in p.runs for f in p.store.file_names(run.name)])
            self.execute(jobs, executor, scheduler, progress)
        return self

    def made_elsewhere(self, p: Planned) -> dict[str, tuple[ResultStore, str]]:
        """Run name -> (the store, the name) of the same run done in another experiment of
        ``p``'s entry, for ``p``'s runs to do: the same frames from the same first box, tracked
        once from it (OPE's run and TRE's first, which starts at frame 1 when its ground truth
        is valid), under ``p``'s run key."""
        if not self.experiment.tracks_once:
            return {}
        others = [e for e in EXPERIMENTS.values() if e.name != self.experiment.name and e.tracks_once
                  and store_folder(self.out, p.name, e).is_dir()]
        todo, found = {run.name for run in p.todo}, {}
        for seq in self.sequences if others and todo else ():
            runs = [run for run in self.by_sequence[seq.name] if run.name in todo]
            twins: dict[tuple, list[tuple[ResultStore, Sequence]]] = {}
            for other in others if runs else ():
                store = ResultStore(store_folder(self.out, p.name, other))
                for twin in _runs_of(other, seq):
                    twins.setdefault(run_identity(twin), []).append((store, twin))
            for run in runs:
                done = next(((store, twin.name) for store, twin in twins.get(run_identity(run), ())
                             if store.status(twin, p.key) == "done"), None)
                if done is not None:
                    found[run.name] = done
        return found

    def execute(self, jobs: int = 1, executor: str = "local", scheduler: str | None = None,
                progress: Progress | None = None) -> None:
        """Copy the runs done in another experiment of their entry (:meth:`made_elsewhere`) or
        in another entry of their key, then track the others, each once (the runs sharing their
        frames together, :mod:`dcfkit.running.lockstep`; the largest first), with ``progress``;
        each run's outcome goes to every entry that gets it."""
        for p in self.entries:
            runs = {run.name: run for run in p.todo}
            for name, (source, source_name) in self.made_elsewhere(p).items():
                if _copied_twin(p, runs[name], source, source_name):
                    p.done.append(name)
        tasks, copies = self.shared()
        for source, targets, name in copies:
            for p in targets:
                p.store.copy_run(source.store, name)
                p.done.append(name)
        if not (jobs == 1 and executor == "local"):
            tasks.sort(key=lambda s: -len(s.task.seq))
        by_task = {id(s.task): s for s in tasks}
        progress = progress or Progress()
        warm_up_compiled([s.task for s in tasks])  # numba compiles here, not in the first runs a bar times
        progress.start([s.task for s in tasks], self.distinct)

        def on_result(task: RunTask, result: dict) -> None:
            shared = by_task[id(task)]
            for p in shared.members[1:]:
                p.store.copy_run(shared.members[0].store, task.seq.name)
            for p in shared.members:
                if result["status"] == "done":
                    p.done.append(task.seq.name)
                else:
                    p.failed[task.seq.name] = result["error"]
            self.tracked.append((shared, result))
            progress.result(shared, result)

        try:
            execute([s.task for s in tasks], on_result, jobs=jobs, executor=executor, scheduler=scheduler,
                    version=self.version, on_frame=progress.frame)
        finally:
            progress.close()


def _copied_twin(p: Planned, run: Sequence, source: ResultStore, source_name: str) -> bool:
    """Copy ``run`` from its twin in another experiment's folder, which this command has not
    claimed; whether the copy is done under ``p``'s key. Another command may have rewritten
    or removed the twin since it was found done: the run is then tracked, not lost."""
    try:
        p.store.copy_run(source, run.name, source_name)
    except StoreError as exc:
        log.warning("%s: tracked instead of copied (%s)", run.name, exc)
        return False
    return p.store.status(run, p.key) == "done"


def _runs_of(experiment: Experiment, seq: Sequence) -> list[Sequence]:
    """``seq``'s runs in ``experiment``; none if it has none (too short for TRE, say)."""
    try:
        return experiment.plan(seq).runs
    except DatasetError:
        return []


def _claim_text(p: Planned, kind: str) -> Callable[[str], str]:
    """How a claim of ``p``'s runs is named in an error: ``drift's results of sequence 'b' to OUT/drift``."""
    return lambda name: f"{p.name}'s results of {kind} {name!r} to {p.store.folder}"
