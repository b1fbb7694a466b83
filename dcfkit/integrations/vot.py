"""Any dcfkit dataset as a VOT toolkit workspace's sequences (``dcfkit export vot``).

The VOT toolkit reads ``WORKSPACE/sequences/list.txt`` and, per sequence, a ``sequence`` file
(``channels.color`` names the frames, ``fps``, ``format=default``), the frames and
``groundtruth.txt``: one ``x,y,w,h`` rectangle a frame in 0-based image coordinates, as dcfkit
keeps boxes (an absent target: ``nan,nan,nan,nan``, as VOT-LT writes it). Frames are linked, not
copied, unless asked: a workspace of a large benchmark costs no disk.
"""
from __future__ import annotations

import math
import os
import shutil
from pathlib import Path
from typing import Iterable

from dcfkit.datasets import Sequence
from dcfkit.errors import DatasetError
from dcfkit.running.files import atomic_write, make_dir

FRAME_DIGITS = 8  # color/00000001.jpg, as the VOT datasets name their frames
DEFAULT_FPS = 30


def export_sequences(sequences: Iterable[Sequence], workspace: Path, copy: bool = False) -> list[str]:
    """Write ``workspace/sequences/``: each sequence's folder and ``list.txt``; returns the
    names. An existing sequence folder is an error (nothing is overwritten)."""
    folder = make_dir(Path(workspace) / "sequences")
    names = []
    for seq in sequences:
        _export(seq, folder / seq.name, copy)
        names.append(seq.name)
    if not names:
        raise DatasetError("no sequence to export")
    atomic_write(folder / "list.txt", "".join(f"{n}\n" for n in names))
    return names


def _export(seq: Sequence, target: Path, copy: bool) -> None:
    suffixes = {Path(f).suffix.lower() for f in seq.frames}
    if len(suffixes) != 1:
        raise DatasetError(f"sequence {seq.name!r}: its frames have several file types ({', '.join(sorted(suffixes))}); "
                           f"VOT names them by one pattern")
    if target.exists():
        raise DatasetError(f"{target} exists: export into an empty workspace")
    (suffix,) = suffixes
    color = make_dir(target / "color")
    for i, frame in enumerate(seq.frames, start=1):
        destination = color / f"{i:0{FRAME_DIGITS}d}{suffix}"
        if copy:
            shutil.copyfile(frame, destination)
        else:
            os.symlink(os.path.abspath(frame), destination)
    atomic_write(target / "groundtruth.txt", "".join(_region(box) + "\n" for box in seq.ground_truth))
    atomic_write(target / "sequence", f"channels.color=color/%0{FRAME_DIGITS}d{suffix}\nformat=default\n"
                                      f"fps={DEFAULT_FPS}\nname={seq.name}\n")


def _region(box) -> str:
    """A 0-based box as VOT writes a rectangle (``nan`` values for an absent target)."""
    if not all(math.isfinite(v) for v in box):
        return "nan,nan,nan,nan"
    return ",".join(f"{float(v):.4f}".rstrip("0").rstrip(".") for v in box)
