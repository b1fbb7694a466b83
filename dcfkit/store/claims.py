"""Claims on the runs of a results folder: two evaluations never write the same run, while runs
on other sequences of one folder may go on alongside, and whatever the number of runs an
evaluation holds two open files at most (docs/evaluation.md, "Running").

``FOLDER/.locks/<owner>.claims`` lists the runs an evaluation writes and ``<owner>.lock``, which
it holds (``flock``) until it ends, says it still runs: a killed one's claims lapse with its
lock. ``.locks/.guard`` is held only while claims are checked and made.
"""
from __future__ import annotations

import contextlib
import json
import logging
import os
import secrets
from pathlib import Path
from typing import Callable, Iterable

from dcfkit.errors import DcfkitError

try:
    import fcntl
except ImportError:  # not POSIX: runs go on unclaimed
    fcntl = None

log = logging.getLogger(__name__)

CLAIMS, LOCK = ".claims", ".lock"


@contextlib.contextmanager
def claimed(folder: Path, names: Iterable[str], command: str, what: Callable[[str], str]):
    """Hold ``names`` (runs of ``folder``) for this process: a :class:`DcfkitError` if another
    live ``command`` holds one of them, naming it with ``what(name)``. Where no lock can be
    taken (not POSIX, a read-only folder, a file system without ``flock``) the run goes on
    unclaimed, with a warning."""
    if fcntl is None:
        yield
        return
    locks = Path(folder) / ".locks"
    mine, held, names = locks / f"{os.getpid()}-{secrets.token_hex(4)}", None, set(names)
    try:
        with contextlib.suppress(FileExistsError):
            locks.mkdir()
        # read-only: flock needs no write access, so another user's guard serves too
        with open(os.open(locks / ".guard", os.O_RDONLY | os.O_CREAT, 0o666)) as guard:
            fcntl.flock(guard, fcntl.LOCK_EX)  # brief: held by others only while they claim
            _check_claims(locks, names, command, what)
            held = open(mine.with_suffix(LOCK), "a+")
            fcntl.flock(held, fcntl.LOCK_EX | fcntl.LOCK_NB)
            mine.with_suffix(CLAIMS).write_text(json.dumps(sorted(names)), encoding="utf-8")
    except OSError as exc:
        if held is not None:
            held.close()
        log.warning("cannot create the lock %s (%s): running without it", exc.filename or mine.with_suffix(LOCK),
                    exc.strerror)
        yield
        return
    try:
        yield
    finally:
        for end in (CLAIMS, LOCK):
            with contextlib.suppress(OSError):
                mine.with_suffix(end).unlink()
        held.close()


def _check_claims(locks: Path, names: set[str], command: str, what: Callable[[str], str]) -> None:
    """Raise if an owner in ``locks`` that is alive, or whose lock cannot be read (another
    user's, or something else in its place), claims one of ``names``; remove dead ones' claims."""
    for claims in locks.glob(f"*{CLAIMS}"):
        lock, unreadable = claims.with_suffix(LOCK), None
        try:
            with open(os.open(lock, os.O_RDONLY)) as owner:  # flock needs no write access
                fcntl.flock(owner, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            pass  # alive
        except OSError as exc:
            if isinstance(exc, FileNotFoundError):  # no lock: its owner ended, or was killed before it locked
                _remove(claims)
                continue
            unreadable = exc.strerror  # cannot tell whether its owner runs: it may
        else:
            _remove(claims, lock)  # its owner was killed, or is removing them as it ends
            continue
        try:
            taken = names.intersection(json.loads(claims.read_text(encoding="utf-8")))
        except (OSError, ValueError, TypeError):
            continue  # removed as it ended, or not a list of runs
        if taken and unreadable:
            raise DcfkitError(f"{claims} claims {what(min(taken))}, and its lock {lock} cannot be read "
                              f"({unreadable}): if no `{command}` writes there, remove both")
        if taken:
            raise DcfkitError(f"another `{command}` is writing {what(min(taken))} (it holds {lock}); "
                              f"wait for it or write elsewhere")


def _remove(*paths: Path) -> None:
    """Unlink ``paths`` as far as possible (one in the way, a folder say, stays and is read as such)."""
    for path in paths:
        with contextlib.suppress(OSError):
            path.unlink()
