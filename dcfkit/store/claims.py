"""Claims on the runs of results folders: two commands never write the same run, while runs
on other sequences of one folder may go on alongside, and whatever the number of runs and
folders a command holds two open files at most (docs/evaluation.md, "Running").

``FOLDER/.locks/<owner>.claims`` lists the runs a command writes there and ``<owner>.lock``,
which it holds (``flock``) until it ends, says it still runs: a killed one's claims lapse with
its lock. The locks of one command in several folders are hard links to one file (a lock is
the file's, whichever name opens it), so an ablation of a thousand variants holds one.
``.locks/.guard`` is held only while claims are checked and made.
"""
from __future__ import annotations

import contextlib
import json
import logging
import os
import secrets
from pathlib import Path
from typing import Callable, Iterable, Mapping

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
    with claimed_folders({Path(folder): (names, what)}, command):
        yield


@contextlib.contextmanager
def claimed_folders(claims: Mapping[Path, tuple[Iterable[str], Callable[[str], str]]], command: str):
    """:func:`claimed` for several folders at once: ``{folder: (names, what)}``, each folder's
    claims checked and made in turn (none held if one is refused), one lock held for all."""
    if fcntl is None:
        yield
        return
    owner = _Owner(f"{os.getpid()}-{secrets.token_hex(4)}")
    try:
        for folder, (names, what) in claims.items():
            owner.claim(Path(folder) / ".locks", set(names), command, what)
        yield
    finally:
        owner.release()


class _Owner:
    """This process's claims: the files it made in each ``.locks`` and the lock files it holds
    open (one, unless a folder's file system takes no hard link to it)."""

    def __init__(self, name: str):
        self.name, self.made, self.held = name, [], []

    def claim(self, locks: Path, names: set[str], command: str, what: Callable[[str], str]) -> None:
        """Check ``locks``'s claims, then lock and claim ``names`` there; a warning, and the
        folder unclaimed, if a lock cannot be made there."""
        mine = locks / self.name
        try:
            with contextlib.suppress(FileExistsError):
                locks.mkdir()
            # read-only: flock needs no write access, so another user's guard serves too
            with open(os.open(locks / ".guard", os.O_RDONLY | os.O_CREAT, 0o666)) as guard:
                fcntl.flock(guard, fcntl.LOCK_EX)  # brief: held by others only while they claim
                _check_claims(locks, names, command, what)
                self._lock(mine.with_suffix(LOCK))
                self.made.append(mine.with_suffix(CLAIMS))
                mine.with_suffix(CLAIMS).write_text(json.dumps(sorted(names)), encoding="utf-8")
        except OSError as exc:
            log.warning("cannot create the lock %s (%s): running without it", exc.filename or mine.with_suffix(LOCK),
                        exc.strerror)

    def _lock(self, path: Path) -> None:
        """Hold a lock at ``path``: a hard link to the one held, else a file of its own."""
        if self.held:
            with contextlib.suppress(OSError):  # another file system, or none that links: a lock of its own
                os.link(self.held[0].name, path)
                self.made.append(path)
                return
        handle = open(path, "a+")
        self.made.append(path)
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            handle.close()
            raise
        self.held.append(handle)

    def release(self) -> None:
        """Remove the claims, then the locks made (a claim never outlives its lock), then let go
        of the locks held."""
        _remove(*sorted(self.made, key=lambda path: path.suffix != CLAIMS))
        for handle in self.held:
            handle.close()


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
