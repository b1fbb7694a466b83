"""Annotation files: boxes and per-frame values, read within bounds (ASCII numbers, line and file sizes)."""
from __future__ import annotations

import math
import os
import re
from pathlib import Path

import numpy as np

from dcfkit.datasets.images import regular_file_bytes
from dcfkit.errors import DatasetError, shown

_SEPARATORS = re.compile(r"[,\s]+")


MAX_TEXT_BYTES = 64 * 2**20  # an annotation file: LaSOT's longest is under 1 MB, a VOT mask file tens of MB


MAX_LINE_CHARS = 4096  # a line of boxes or flags (a VOT mask line is read by its own layout)


# a number as the toolkits write one (and libtrax's atof reads): ASCII digits only (float() also
# takes '٣' and '2_0'); compile it with re.IGNORECASE and re.ASCII
NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?|[-+]?(?:nan|inf|infinity)"


_NUMBER = re.compile(NUMBER, re.IGNORECASE | re.ASCII)


def read_text(path: Path) -> str:
    """A benchmark text file (UTF-8, optional BOM): a regular file (a FIFO would block,
    /dev/zero never end) of at most :data:`MAX_TEXT_BYTES`; :class:`DatasetError` naming it
    otherwise."""
    try:
        data = regular_file_bytes(path, str(path), MAX_TEXT_BYTES,
                                   f": an annotation file of more than {MAX_TEXT_BYTES:.3g} bytes is not one")
        return data.decode("utf-8-sig")
    except FileNotFoundError:
        raise DatasetError(f"annotation file not found: {path}") from None
    except UnicodeDecodeError as exc:
        raise DatasetError(f"{path}: not a text annotation file (byte {exc.start} is not UTF-8)") from None
    except OSError as exc:
        raise DatasetError(f"cannot read {path}: {exc.strerror}") from None


def listed(annotation: Path) -> bool:
    """Whether a sequence's annotation file is there (a folder of a benchmark lists the
    sequence): whatever it is, a FIFO or a link to /dev/zero too, so that reading it says what
    is wrong instead of the sequence vanishing from the list."""
    return os.path.lexists(annotation)


def parse_number(field: str) -> float:
    """A number of an annotation file (ASCII digits, ``nan`` and ``inf`` as written); ValueError
    for anything else Python's ``float`` would take."""
    if not _NUMBER.fullmatch(field):
        raise ValueError(f"could not convert {field[:40]!r} to a number")
    value = float(field)
    if math.isinf(value) and "inf" not in field.lower():
        raise ValueError(f"{field[:40]!r} is beyond the range of a float")
    return value


def annotation_lines(text: str) -> list[str]:
    """The lines of an annotation file, broken at line feeds alone (``str.splitlines`` also
    breaks at form feeds and U+2028, and messages would name the wrong line)."""
    return [line.removesuffix("\r") for line in text.split("\n")]


def _fields(line: str, path: Path, n: int) -> list[str]:
    """The values of line ``n`` (0-based) of ``path``; a line too long to be one is refused
    before it is split."""
    if len(line) > MAX_LINE_CHARS:
        raise DatasetError(f"{path}, line {n + 1}: {len(line)} characters, too long for a line of boxes or flags "
                           f"(at most {MAX_LINE_CHARS})")
    return [f for f in _SEPARATORS.split(line.strip()) if f]


def read_boxes(path: str | os.PathLike, one_based: bool = True) -> np.ndarray:
    """Read one ``x,y,w,h`` box per line (commas, tabs or spaces) as ``(N, 4) float64``.

    With ``one_based`` (the benchmark convention), 1 is subtracted from x and y so the
    result is 0-based. ``NaN`` values are kept. Trailing blank lines are ignored; a blank
    or malformed line inside the file is a :class:`DatasetError` naming file and line.
    """
    path = Path(path)
    text = read_text(path).rstrip()
    lines = annotation_lines(text) if text else []
    boxes = np.empty((len(lines), 4), dtype=np.float64)
    for n, line in enumerate(lines):
        fields = _fields(line, path, n)
        try:
            if len(fields) != 4:
                raise ValueError
            boxes[n] = [parse_number(f) for f in fields]
        except ValueError:
            raise DatasetError(
                f"{path}, line {n + 1}: expected 4 numbers 'x,y,w,h' separated by commas, "
                f"tabs or spaces, got {shown(line.strip())}") from None
    if one_based:
        boxes[:, :2] -= 1.0
    return boxes


_FIELD = re.compile(r"[^,\s]+")


MAX_FRAME_VALUE = 2**31 - 1  # flags and cover levels are small; a larger value is no flag


def read_frame_values(path: Path, n_frames: int) -> np.ndarray:
    """One whole number per frame, separated by commas, spaces or new lines (LaSOT's
    ``full_occlusion.txt`` holds one line, GOT-10k's ``.label`` files one value a line), as
    ``(n_frames,) int64``; :class:`DatasetError` naming the file and the line of a value that is
    not a whole number, or the count when it is not ``n_frames``."""
    values = []
    for n, line in enumerate(annotation_lines(read_text(path))):
        for match in _FIELD.finditer(line):  # one at a time: LaSOT's single line may be long
            field = match.group()
            try:
                value = parse_number(field)
                if not value.is_integer() or abs(value) > MAX_FRAME_VALUE:
                    raise ValueError
            except ValueError:
                raise DatasetError(f"{path}, line {n + 1}: expected whole numbers, one per frame, got {shown(field)} "
                                   f"for frame {len(values) + 1}") from None
            values.append(int(value))
            if len(values) > n_frames:
                raise DatasetError(f"{path}: more values than its {n_frames} frames; one value per frame is required")
    if len(values) != n_frames:
        raise DatasetError(f"{path}: {len(values)} values for {n_frames} frames; one value per frame is required")
    return np.array(values, dtype=np.int64)


def read_flags(path: Path, names: tuple[str, ...]) -> dict[str, bool]:
    """One line of 0/1 flags, one per name in ``names`` (e.g. a UAV123 att file)."""
    fields = _fields(read_text(path).strip(), path, 0)
    if len(fields) != len(names) or any(f not in ("0", "1") for f in fields):
        raise DatasetError(
            f"{path}, line 1: expected {len(names)} 0/1 flags ({' '.join(names)}), "
            f"got {shown(' '.join(fields))}")
    return {name: f == "1" for name, f in zip(names, fields)}
