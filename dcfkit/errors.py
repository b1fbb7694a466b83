"""Exceptions raised by dcfkit. Each names what was wrong and where."""
import reprlib
import traceback
from typing import Any

SHOWN_CHARS = 200  # the most of a value or key an error message shows: a config value may be megabytes


class DcfkitError(Exception):
    """Base class of every error dcfkit raises on purpose."""


class ConfigError(DcfkitError, ValueError):
    """A config file, key or value is wrong (the message names the file and key)."""


class RegistryError(DcfkitError, LookupError):
    """A component name is unknown or registered twice."""


class InputError(DcfkitError, ValueError):
    """An image or box given to a tracker is unusable (the message says which frame)."""


class TrackingError(DcfkitError, RuntimeError):
    """Tracking could not continue on a frame (the message names the frame)."""


class DatasetError(DcfkitError, ValueError):
    """A benchmark folder, annotation file or sequence name is wrong (the message says where)."""


class MissingDependency(DcfkitError, ImportError):
    """An optional package is not installed (the message names the extra that installs it)."""


class DcfkitWarning(UserWarning):
    """Base class of every warning dcfkit gives on purpose (the CLI prints each as one line)."""


class InputWarning(DcfkitWarning, RuntimeWarning):
    """An input dcfkit reads, but maybe not as its author meant (the message says how)."""


def shown(value: Any) -> str:
    """``repr(value)`` in at most :data:`SHOWN_CHARS` characters, whatever the value's size or depth."""
    short = reprlib.Repr()  # its limits are per level: a few items, a few levels, a few characters each
    short.maxlevel, short.maxstring, short.maxother = 3, SHOWN_CHARS, SHOWN_CHARS
    try:
        text = short.repr(value)
    except Exception:  # a repr that fails: an int over Python's 4300 digits, a broken object
        text = f"<{type(value).__name__}>"
    return clip(text)


def printable(value: Any) -> str:
    """``str(value)`` with each character that is not printable (a line break, an escape) as its
    Python escape: one line, whatever a folder name or environment value holds."""
    return "".join(c if c.isprintable() else c.encode("unicode_escape").decode() for c in str(value))


def clip(text: str) -> str:
    """``text`` cut to at most :data:`SHOWN_CHARS` characters (a key or path from a config, for a message)."""
    return text if len(text) <= SHOWN_CHARS else text[:SHOWN_CHARS - 3] + "..."


def describe_error(exc: BaseException) -> str:
    """``Type: message (at file:line)``: an exception as one line that says where it was raised."""
    text = f"{type(exc).__name__}: {exc}" if str(exc) else type(exc).__name__
    if isinstance(exc, SyntaxError) and exc.filename:
        return f"{text} (at {exc.filename}:{exc.lineno})"
    frames = traceback.extract_tb(exc.__traceback__)
    return f"{text} (at {frames[-1].filename}:{frames[-1].lineno})" if frames else text
