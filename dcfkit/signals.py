"""Signal handlers replaced for the length of a block: SIGTERM and SIGHUP raised as Ctrl-C is
(:class:`Interrupted`) or held back while a final write runs, and the registry's noting of
interrupts while plugins load."""
from __future__ import annotations

import contextlib
import os
import signal
import threading
from typing import Callable, Iterable


@contextlib.contextmanager
def handlers_replaced(signums: Iterable[int], replacement: Callable):
    """In the block, each signal is handled by ``replacement(previous handler)`` (None: left as
    it is); yields the handlers replaced, signal -> previous. Off the main thread, where Python
    can set no handler, nothing changes and None is yielded."""
    if threading.current_thread() is not threading.main_thread():
        yield None
        return
    saved = {}
    try:
        for s in signums:
            previous = signal.getsignal(s)
            handler = replacement(previous)
            if handler is not None and previous is not None:  # None: a handler set outside Python
                signal.signal(s, handler)
                saved[s] = previous
        yield saved
    finally:
        for s, previous in saved.items():
            signal.signal(s, previous)


class Interrupted(KeyboardInterrupt):
    """SIGTERM or SIGHUP, raised in the main thread like Ctrl-C so that ``finally`` blocks
    keep what was computed."""

    def __init__(self, signum: int):
        super().__init__(signal.Signals(signum).name)
        self.signum = signum


TERMINATION = tuple(getattr(signal, name) for name in ("SIGTERM", "SIGHUP") if hasattr(signal, name))


INTERRUPTS = (signal.SIGINT, *TERMINATION)  # Ctrl-C too


def _termination_handled_by(handler, signums=TERMINATION):
    """Handle ``signums`` (SIGTERM and SIGHUP) with ``handler`` in the block, except a signal
    ignored when it starts (``nohup`` ignores SIGHUP); yields the handlers it replaced (None
    off the main thread, where signals are left alone)."""
    return handlers_replaced(signums, lambda previous: None if previous is signal.SIG_IGN else handler)


def _interrupt(signum, frame):
    raise Interrupted(signum)


def interrupt_on_termination():
    """Turn SIGTERM and SIGHUP into :class:`Interrupted` while the block runs (e.g. a run under
    ``timeout`` or a closed terminal keeps its boxes, as Ctrl-C does)."""
    return _termination_handled_by(_interrupt)


@contextlib.contextmanager
def termination_deferred(signums=TERMINATION):
    """Hold ``signums`` (SIGTERM and SIGHUP; :data:`INTERRUPTS` adds Ctrl-C) back while the
    block runs (a final write is never cut short); one that arrived meanwhile is handled as it
    would have been, when the block ends."""
    arrived = []
    with _termination_handled_by(lambda signum, frame: arrived.append(signum), signums) as saved:
        yield
    if arrived and saved is not None:
        handler = saved[arrived[0]]
        if callable(handler):
            handler(arrived[0], None)
        else:  # the default action: end the process, as the signal would have
            os.kill(os.getpid(), arrived[0])
