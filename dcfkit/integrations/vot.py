"""Any dcfkit dataset as a VOT toolkit workspace's sequences (``dcfkit export vot``).

The VOT toolkit reads ``WORKSPACE/sequences/list.txt`` and, per sequence, a ``sequence`` file
(``channels.color`` names the frames, ``fps``, ``format=default``), the frames and
``groundtruth.txt``: one ``x,y,w,h`` rectangle a frame in 0-based image coordinates, as dcfkit
keeps boxes (an absent target: ``nan,nan,nan,nan``, as VOT-LT writes it). Frames are linked, not
copied, unless asked: a workspace of a large benchmark costs no disk.

An export adds to a workspace: ``list.txt`` keeps its entries, nothing is overwritten, and each
sequence's folder is written as ``.<name>.partial`` and renamed when complete, so an export
stopped half-way is resumed by running it again.
"""
from __future__ import annotations

import math
import os
import shutil
from pathlib import Path
from typing import Iterable

from dcfkit.datasets import Sequence
from dcfkit.datasets.layout import sequence_name_problem
from dcfkit.errors import DatasetError, clip, shown
from dcfkit.store.files import StoreError, atomic_write, make_dir

FRAME_DIGITS = 8  # color/00000001.jpg, as the VOT datasets name their frames
DEFAULT_FPS = 30  # the VOT toolkit's own default: written for a dataset whose frame rate dcfkit does not know
FRAME_RATES = {  # Sequence.dataset -> the frame rate of its frames
    "uav123": 30, "uav123_20l": 30,  # recorded at 30 fps (Mueller et al., ECCV 2016)
    "uav123_10fps": 10,  # UAV123 with every third frame
    "got10k_train": 10, "got10k_val": 10, "got10k_test": 10,  # annotated at 10 Hz (meta_info.ini's anno_fps)
}
PARTIAL = ".partial"  # a sequence folder being written: sequences/.<name>.partial


def frame_rate(seq: Sequence) -> int | None:
    """The frame rate of ``seq``'s dataset, or None when dcfkit does not know it."""
    return FRAME_RATES.get(seq.dataset)


def export_sequences(sequences: Iterable[Sequence], workspace: Path, copy: bool = False) -> dict[str, list[str]]:
    """Add ``sequences`` to ``workspace/sequences/``: each one's folder, its name appended to
    ``list.txt`` (whose entries are kept). Every name and frame type is checked before anything
    is written. A sequence whose folder is there with the same files is skipped (a rerun
    resumes); a folder of its name holding anything else is an error (nothing is overwritten).

    Returns ``{"written", "skipped", "listed"}``: the names exported now, those already there,
    and every entry of ``list.txt``."""
    seqs = _checked(list(sequences))
    folder = make_dir(Path(workspace) / "sequences")
    listed = _listed(folder / "list.txt")
    written, skipped = [], []
    for seq in seqs:
        files = _files(seq)
        if _present(folder / seq.name, files, len(seq)):
            skipped.append(seq.name)
        else:
            _export(seq, folder, files, copy)
            written.append(seq.name)
    names = list(dict.fromkeys(listed + [seq.name for seq in seqs]))
    if names != listed:
        atomic_write(folder / "list.txt", "".join(f"{n}\n" for n in names))
    return {"written": written, "skipped": skipped, "listed": names}


def _checked(seqs: list[Sequence]) -> list[Sequence]:
    """``seqs`` if each can be written: a name that is one line of ``list.txt`` and one folder
    (:func:`~dcfkit.datasets.layout.sequence_name_problem`), given once, with its whole ground
    truth (not a test split's) and frames of one file type."""
    if not seqs:
        raise DatasetError("no sequence to export")
    seen = set()
    for seq in seqs:
        problem = sequence_name_problem(seq.name)
        if problem is None and seq.name in seen:
            problem = "is given twice"
        if problem is not None:
            raise DatasetError(f"export vot: sequence name {shown(seq.name)} {problem}; nothing was written")
        seen.add(seq.name)
        if seq.ground_truth_withheld:  # VOT would read the NaN rows of a test split as an absent target
            raise DatasetError(f"export vot: sequence {seq.name!r}: its ground truth after frame 1 is withheld (a test "
                               f"split), and VOT would read it as an absent target; nothing was written")
        suffixes = {Path(f).suffix.lower() for f in seq.frames}
        if len(suffixes) != 1:
            raise DatasetError(f"sequence {seq.name!r}: its frames have several file types "
                               f"({', '.join(sorted(suffixes))}); VOT names them by one pattern")
    return seqs


def _listed(path: Path) -> list[str]:
    """The entries of an existing ``list.txt`` (none if there is none), in order."""
    if not path.exists():
        return []
    try:
        return list(dict.fromkeys(line.strip() for line in path.read_text(encoding="utf-8").splitlines()
                                  if line.strip()))
    except (OSError, UnicodeDecodeError) as exc:
        raise DatasetError(f"{clip(str(path))}: cannot read the workspace's list ({exc})") from None


def _files(seq: Sequence) -> dict[str, str]:
    """The text files of ``seq``'s folder: ``sequence`` and ``groundtruth.txt``."""
    suffix = Path(seq.frames[0]).suffix.lower()
    return {"sequence": f"channels.color=color/%0{FRAME_DIGITS}d{suffix}\nformat=default\n"
                        f"fps={frame_rate(seq) or DEFAULT_FPS}\nname={seq.name}\n",
            "groundtruth.txt": "".join(_region(box) + "\n" for box in seq.ground_truth)}


def _present(target: Path, files: dict[str, str], frames: int) -> bool:
    """Whether ``target`` already holds this export (its files and frame count); False if
    there is no ``target``, a :class:`DatasetError` if it holds anything else."""
    if not os.path.lexists(target):
        return False
    if not target.exists():  # a dangling link: "exists" would puzzle
        raise DatasetError(f"{clip(str(target))} is a symbolic link (to {clip(os.readlink(target))}, which does not "
                           f"exist): nothing is overwritten; remove it or export into another workspace")
    try:
        differs = [name for name, text in files.items() if (target / name).read_text(encoding="utf-8") != text]
        entries = list((target / "color").iterdir())
        count, broken = len(entries), sum(1 for e in entries if not e.exists())
    except (OSError, UnicodeDecodeError):
        differs, count, broken = list(files), None, 0
    if count != frames:
        differs.append(f"color/ ({count if count is not None else 'no'} frames, not {frames})")
    if broken:  # links to frames moved since: the toolkit could read none of them
        differs.append(f"color/ ({broken} of its frames lead nowhere)")
    if differs:
        raise DatasetError(f"{clip(str(target))} exists and is not this export ({', '.join(differs)} differ): "
                           f"nothing is overwritten; remove it or export into another workspace")
    return True


def _export(seq: Sequence, folder: Path, files: dict[str, str], copy: bool) -> None:
    """Write ``seq`` into ``folder/.<name>.partial`` (replacing one left by an export that
    stopped), then rename it ``folder/<name>``."""
    partial = folder / f".{seq.name}{PARTIAL}"
    suffix = Path(seq.frames[0]).suffix.lower()
    try:
        _remove(partial)
        color = make_dir(partial / "color")
        for i, frame in enumerate(seq.frames, start=1):
            destination = color / f"{i:0{FRAME_DIGITS}d}{suffix}"
            if copy:
                shutil.copyfile(frame, destination)
            else:
                os.symlink(os.path.abspath(frame), destination)
        for name, text in files.items():
            atomic_write(partial / name, text)
        os.rename(partial, folder / seq.name)
    except OSError as exc:
        raise StoreError(f"sequence {seq.name!r}: cannot export it into {clip(str(folder))}: {exc.strerror or exc}"
                         + (f" ({clip(str(exc.filename))})" if exc.filename else "")) from None


def _remove(path: Path) -> None:
    """Remove ``path``, a folder's tree (its links, not what they point to) or a file, if there."""
    if path.is_dir() and not path.is_symlink():
        shutil.rmtree(path)
    elif os.path.lexists(path):
        path.unlink()


def _region(box) -> str:
    """A 0-based box as VOT writes a rectangle (``nan`` values for an absent target)."""
    if not all(math.isfinite(v) for v in box):
        return "nan,nan,nan,nan"
    return ",".join(f"{float(v):.4f}".rstrip("0").rstrip(".") for v in box)
