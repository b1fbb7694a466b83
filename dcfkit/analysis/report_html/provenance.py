"""What produced a report's results, read from the result sidecars (:mod:`dcfkit.store.results`):
commands, dcfkit and plugin versions, run keys (config hashes), machines, platforms
(:mod:`dcfkit.store.platforms`), times, config.

Sidecars written before dcfkit recorded the command and the machine lack them; they are
then "not recorded", and imported result files (no sidecars) have nothing recorded. A page is
shared: it shows no host name or working directory (older sidecars recorded them), paths
relative to the page's folder and the home folder as ``~``.
"""
from __future__ import annotations

from collections import Counter
from pathlib import Path
from typing import Iterable, Mapping

from dcfkit.store import platforms
from dcfkit.store.provenance import (
    command_line,
    dcfkit_version,
    invocation,
    machine,
    now,
    shared_path,
    without_home,
)
from dcfkit.store.results import ResultStore

NOT_RECORDED = "not recorded"


def describe_machine(record) -> str:
    """``CPU, N cores, OS, Python x.y`` of a :func:`dcfkit.store.provenance.machine` record
    (an older record's ``host`` left out)."""
    if not isinstance(record, Mapping):
        return NOT_RECORDED
    parts = [str(record[k]) for k in ("cpu",) if record.get(k)]
    if record.get("cores"):
        parts.append(f"{record['cores']} cores")
    parts += [str(record[k]) for k in ("system",) if record.get(k)]
    if record.get("python"):
        parts.append(f"Python {record['python']}")
    return ", ".join(parts) or NOT_RECORDED


def _counted(values: Iterable) -> list[list]:
    """``[[value, count], ...]``, most frequent first (a folder usually holds one of each)."""
    return [[value, count] for value, count in Counter(values).most_common()]


def _command(meta: Mapping) -> str:
    """The command as one shell line, the home folder as ``~`` (an older sidecar's ``cwd`` left out)."""
    line = command_line(meta)
    return NOT_RECORDED if line is None else without_home(line)


def describe_sources(record) -> str:
    """A sidecar's ``source`` as ``dcfkit 1a2b3c4d5e6f with uncommitted changes, code 0123abcd...;
    plugin ...`` (``code``: the digest of dcfkit's box code, recorded since it enters the run key)."""
    if not isinstance(record, dict):
        return NOT_RECORDED
    parts = []
    for name, found in record.items():
        found = found if isinstance(found, dict) else {}
        if not found.get("commit"):
            part = f"{name}: no git commit recorded (a release)"
        else:
            part = f"{name} {str(found['commit'])[:12]}" + (" with uncommitted changes" if found.get("dirty") else "")
        parts.append(part + (f", code {found['code']}" if isinstance(found.get("code"), str) else ""))
    return "; ".join(parts)


def folder_provenance(folder: Path, names: Iterable[str], base: Path | None = None) -> dict:
    """What the sidecars of sequences ``names`` in ``folder`` record: ``folder`` (relative to
    ``base``, the page's folder: :func:`~dcfkit.store.provenance.shared_path`),
    ``sequences`` (sidecars read), ``run_keys``, ``versions``, ``plugins``, ``sources`` (git
    commits), ``commands``,
    ``machines``, ``platforms`` (each ``[[value, sequences], ...]``), ``times`` (first, last) and
    ``config`` (the first sidecar's)."""
    store = ResultStore(folder)
    metas = [m for m in (store.sidecar(n) for n in names) if m is not None]
    if not metas:
        return {"folder": shared_path(folder, base), "sequences": 0}
    times = sorted(str(m["time"]) for m in metas if m.get("time"))
    return {
        "folder": shared_path(folder, base),
        "sequences": len(metas),
        "run_keys": _counted(str(m.get("run_key", m.get("config_hash", NOT_RECORDED))) for m in metas),
        "versions": _counted(str(m.get("dcfkit_version", NOT_RECORDED)) for m in metas),
        "plugins": _counted(", ".join(map(str, m.get("plugins") or [])) or "none" for m in metas),
        "sources": _counted(describe_sources(m.get("source")) for m in metas),
        "commands": _counted(_command(m) for m in metas),
        "machines": _counted(describe_machine(m.get("machine")) for m in metas),
        "platforms": _counted(platforms.describe(m.get("platform")) for m in metas),
        "times": [times[0], times[-1]] if times else [],
        "config": metas[0].get("config"),
    }


def this_process() -> dict:
    """The command, dcfkit version, machine and time of the process writing the report."""
    here = invocation()
    return {"command": _command(here), "dcfkit": dcfkit_version(), "machine": describe_machine(machine()),
            "platform": platforms.describe(platforms.record()), "time": now()}
