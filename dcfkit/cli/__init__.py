"""The ``dcfkit`` command line: argument parsing and printing only; the work is the
library's (:mod:`dcfkit.running.evaluation`, :mod:`dcfkit.ablation`, :mod:`dcfkit.analysis.report`, ...)."""
from __future__ import annotations

import contextlib
import errno
import sys
import warnings

from dcfkit.cli.parser import build_parser, named_command
from dcfkit.errors import DcfkitError, DcfkitWarning, clip
from dcfkit.store.provenance import running_command
from dcfkit.signals import interrupt_on_termination

__all__ = ["build_parser", "main"]


def _one_line_warnings(show):
    """``warnings.showwarning`` for the CLI: a warning of dcfkit's (a plugin problem, an input
    read with a caveat) is one ``warning: ...`` line, not a source location inside dcfkit."""
    def showwarning(message, category, filename, lineno, file=None, line=None):
        if issubclass(category, DcfkitWarning):
            print(f"warning: {message}", file=sys.stderr)
        else:
            show(message, category, filename, lineno, file, line)
    return showwarning


def main(argv: list[str] | None = None) -> int:
    args = build_parser(only=named_command(sys.argv[1:] if argv is None else argv)).parse_args(argv)
    given = contextlib.nullcontext() if argv is None else running_command(["dcfkit", *argv])
    with warnings.catch_warnings(), interrupt_on_termination(), given:  # SIGTERM/SIGHUP end a command as Ctrl-C does
        warnings.showwarning = _one_line_warnings(warnings.showwarning)
        try:
            return args.func(args) or 0
        except DcfkitError as exc:
            print(f"dcfkit {args.command}: error: {exc}", file=sys.stderr)
            return 2
        except KeyboardInterrupt as exc:
            print(f"dcfkit {args.command}: interrupted{f' ({exc})' if str(exc) else ''}", file=sys.stderr)
            return 128 + getattr(exc, "signum", 2)
        except BrokenPipeError:  # e.g. piped into head
            sys.stderr.close()
            return 0
        except OSError as exc:  # pathlib's is_file() and the like raise it for any argument or config value
            if exc.errno != errno.ENAMETOOLONG:
                raise
            print(f"dcfkit {args.command}: error: a name too long for the file system: "
                  f"{clip(str(exc.filename))}", file=sys.stderr)
            return 2
