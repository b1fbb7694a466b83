"""Exceptions raised by dcfkit. Each names what was wrong and where."""
import contextlib
import traceback


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


def describe_error(exc: BaseException) -> str:
    """``Type: message (at file:line)``: an exception as one line that says where it was raised."""
    text = f"{type(exc).__name__}: {exc}" if str(exc) else type(exc).__name__
    if isinstance(exc, SyntaxError) and exc.filename:
        return f"{text} (at {exc.filename}:{exc.lineno})"
    frames = traceback.extract_tb(exc.__traceback__)
    return f"{text} (at {frames[-1].filename}:{frames[-1].lineno})" if frames else text


@contextlib.contextmanager
def blamed_on(what: str):
    """Inside, an unexpected exception (a component's bug) becomes a :class:`TrackingError`
    ``"<what> raised <Type: message (at file:line)>"``; dcfkit's own errors pass through."""
    try:
        yield
    except DcfkitError:
        raise
    except Exception as exc:
        raise TrackingError(f"{what} raised {describe_error(exc)}") from exc
