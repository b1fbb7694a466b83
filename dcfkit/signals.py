"""Signal handlers replaced for the length of a block (dcfkit.running.tracking's interrupts, the
registry's noting of interrupts while plugins load)."""
from __future__ import annotations

import contextlib
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
