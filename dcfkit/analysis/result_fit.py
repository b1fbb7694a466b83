"""Whether result folders fit the sequences a report scores, said once before any is read:
results of other sequences (another dataset) and results of another length (a smoke run's,
``--max-frames N``, reported without the flag, or whole runs reported with one) would otherwise
be left out file by file, each with a warning, and end in "no sequence has a result"."""
from __future__ import annotations

from pathlib import Path
from typing import Mapping
from typing import Sequence as Seq

from dcfkit.datasets import DatasetError, Sequence
from dcfkit.errors import clip, printable
from dcfkit.store.results import ResultStore, result_files

NAMES = 5  # the most sequence names a message lists


def check_results_fit(out_dir, folders: Mapping[str, Path], runs: Seq[Sequence], missing: str = "skip",
                      cut: int | None = None) -> None:
    """A :class:`DatasetError` when the results in ``folders`` (tracker -> folder) cannot be
    scored on ``runs``: no folder holds a result of any of them (or, under ``missing="skip"``,
    one does not), or a tracker's stored runs have other frame counts than ``runs`` (its
    sidecars' ``frames``) and were all made with one ``--max-frames`` (or none) that is not
    the report's (``cut``: its ``--max-frames``). Imported results (no sidecar) are taken as
    fitting."""
    by_name = {r.name: r for r in runs}
    files = {t: set(result_files(folder)) for t, folder in folders.items()}
    unmatched = [t for t, found in files.items() if not found & by_name.keys()]
    if unmatched and (len(unmatched) == len(files) or missing == "skip"):
        raise DatasetError(_other_sequences(out_dir, folders, unmatched, files, runs))
    made: dict[int | None, dict[str, list[str]]] = {}  # --max-frames -> tracker -> its runs of another length
    for tracker, folder in folders.items():
        found = _other_lengths(folder, [by_name[n] for n in sorted(files[tracker] & by_name.keys())], cut)
        if found is not None:
            made.setdefault(found[0], {})[tracker] = found[1]
    if made:  # the first cut found: one message, not one per tracker
        limit, trackers = next(iter(made.items()))
        raise DatasetError(_lengths_message(out_dir, limit, trackers, cut))


def _lengths_message(out_dir, limit: int | None, trackers: Mapping[str, list[str]], cut: int | None) -> str:
    """What is wrong with the lengths of ``trackers``' runs (tracker -> run names), made with
    ``--max-frames limit`` (None: whole runs), for a report with ``--max-frames cut``."""
    whose = f"the results of {_names(trackers)} in {clip(str(out_dir))}"
    runs = _names(dict.fromkeys(n for names in trackers.values() for n in names))
    if limit is None:
        return (f"{whose} are whole runs ({runs}: longer than this report's --max-frames {cut} leaves): report "
                f"them without --max-frames")
    said = f"--max-frames {cut}" if cut is not None else "no --max-frames"
    return (f"{whose} were cut by --max-frames {limit} (their runs of {runs} hold at most {limit} frames) and this "
            f"report has {said}: report them with --max-frames {limit}")


def _names(names, total: int | None = None) -> str:
    names = list(names)
    total = len(names) if total is None else total
    shown = ", ".join(printable(n) for n in names[:NAMES])
    return shown + (f" and {total - NAMES:,} more" if total > NAMES else "")


def _other_sequences(out_dir, folders: Mapping[str, Path], unmatched: list[str], files: Mapping[str, set],
                     runs: Seq[Sequence]) -> str:
    """Which results are of which sequences, when some tracker has none of ``runs``."""
    held = sorted({n for t in unmatched for n in files[t]})
    wanted = _names((r.name for r in runs), len(runs))
    whose = (f"the results in {clip(str(out_dir))}" if len(unmatched) == len(folders)
             else f"the results of {_names(unmatched)}")
    if not held:
        return f"{whose}: no result file (<sequence>.txt) in {_names(str(folders[t]) for t in unmatched)}"
    return (f"{whose} are of other sequences than the {len(runs):,} scored here ({wanted}): they are of "
            f"{_names(held)}; report them on the dataset they were run on (--dataset, --root, --sequences)"
            + ("" if len(unmatched) == len(folders) else ", or leave those trackers out (--trackers)"))


def _other_lengths(folder: Path, matched: list[Sequence], cut: int | None) -> tuple[int | None, list[str]] | None:
    """(the ``--max-frames`` they were made with, None for whole runs; their names) when every
    stored run of ``matched`` in ``folder`` that has a sidecar has another frame count than its
    run and all were made with one ``--max-frames`` (or none) that is not ``cut``; else None."""
    store, metas = ResultStore(folder), {}
    for run in matched:  # the first run that fits ends the search: a report reads one sidecar a tracker
        meta = store.sidecar(run.name)
        if isinstance(meta, dict) and isinstance(meta.get("frames"), int):
            if meta["frames"] == len(run):
                return None
            metas[run.name] = meta
    other = [run for run in matched if run.name in metas]
    if not other:
        return None
    made = {_max_frames(metas[run.name]) for run in other}
    if made == {UNKNOWN}:  # no command recorded: a smoke run of N leaves N frames of every longer run
        frames = {metas[run.name]["frames"] for run in other}
        made = frames if len(frames) == 1 and all(len(run) > min(frames) for run in other) else made
    if len(made) != 1 or UNKNOWN in made:
        return None
    (limit,) = made
    if limit == cut or (limit is None and not all(metas[run.name]["frames"] > len(run) for run in other)):
        return None  # the same cut, yet other lengths: other data (each file's warning says so)
    return limit, [run.name for run in other]


UNKNOWN = "unknown"  # a sidecar that records no command (older dcfkit)


def _max_frames(meta: Mapping) -> int | str | None:
    """The N of the ``--max-frames N`` in the command a sidecar records, None if it has none,
    :data:`UNKNOWN` if no command is recorded."""
    argv = meta.get("command")
    if not isinstance(argv, list):
        return UNKNOWN
    for i, arg in enumerate(argv):
        value = argv[i + 1] if arg == "--max-frames" and i + 1 < len(argv) else (
            arg.partition("=")[2] if isinstance(arg, str) and arg.startswith("--max-frames=") else None)
        if isinstance(value, str) and value.isdigit():
            return int(value)
    return None


def other_folders(out_dir, sub: str = "") -> dict[str, Path]:
    """Sub-folder name -> folder (its ``sub`` folder, if it has one) of each sub-folder of
    ``out_dir`` that holds result files: where a report that found none of its sequences looks."""
    out_dir = Path(out_dir)
    if not out_dir.is_dir():
        return {}
    found = {}
    for folder in sorted(p for p in out_dir.iterdir() if p.is_dir() and not p.name.startswith(".")):
        folder = folder / sub if sub and (folder / sub).is_dir() else folder
        if result_files(folder):
            found[folder.name if not sub else folder.parent.name] = folder
    return found
