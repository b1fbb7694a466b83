"""GOT-10k: ``ROOT/{train,val,test}/<seq>/%08d.jpg`` with ``groundtruth.txt`` beside the
frames (``x,y,w,h`` a line, 1-based: the toolkit's author, got-10k/toolkit issue 6), and in
train and val the per-frame ``absence.label``, ``cover.label`` and ``cut_by_image.label`` and
``meta_info.ini``; ``ROOT/<split>/list.txt`` names the sequences. ROOT may also be the split
folder itself (``.../GOT-10k/val``).

A frame whose ``cover.label`` is 0 (the target fully hidden; without that file, one whose
``absence.label`` is 1) gets a NaN row: the GOT-10k report scores only frames with cover > 0.
The test split publishes frame 1's box only: its sequences are tracked over every frame
(``%08d.jpg`` from 1) and marked ``ground_truth_withheld`` (results go to the server).
"""
from __future__ import annotations

from pathlib import Path
from typing import Callable

import numpy as np

from dcfkit.datasets.annotations import listed, read_boxes, read_frame_values
from dcfkit.datasets.base import (
    DatasetError,
    Sequence,
    annotated_frames,
    held_out_sequence,
    require_root,
    select_sequences,
)
from dcfkit.datasets.layout import Evidence, register_layout

SPLITS = ("train", "val", "test")


def _find_split(root: Path, split: str) -> Path | None:
    """``ROOT/<split>``, or ROOT itself when it is named after the split; None otherwise."""
    if (root / split).is_dir():
        return root / split
    return root if root.name.lower() == split else None


def split_folder(root, split: str) -> Path:
    """``ROOT/<split>``, or ROOT itself when it is that split's folder; DatasetError otherwise."""
    root = require_root(root, f"GOT-10k {split}")
    folder = _find_split(root, split)
    if folder is not None:
        return folder
    present = [s for s in SPLITS if (root / s).is_dir()]
    held = f"it holds {', '.join(present)}" if present else "expected ROOT/train, ROOT/val, ROOT/test"
    raise DatasetError(f"GOT-10k {split}: folder not found: {root / split} ({held}; ROOT may also be the "
                       f"'{split}' folder itself)")


def invisible_frames(folder: Path, n_frames: int) -> np.ndarray:
    """``(n_frames,) bool``: cover 0 in ``cover.label``, else absence 1 in ``absence.label``,
    else none (a copy without the labels)."""
    if (folder / "cover.label").is_file():
        return read_frame_values(folder / "cover.label", n_frames) == 0
    if (folder / "absence.label").is_file():
        return read_frame_values(folder / "absence.label", n_frames) == 1
    return np.zeros(n_frames, dtype=bool)


def _annotated(name: str, folder: Path, split: str) -> Sequence:
    anno = folder / "groundtruth.txt"
    boxes = read_boxes(anno)
    frames = annotated_frames(folder, "%08d.jpg", boxes, anno, f"GOT-10k {name}")
    boxes[invisible_frames(folder, len(boxes))] = np.nan
    return Sequence(name, frames, boxes, {}, f"got10k_{split}", anno)


def _first_box_only(name: str, folder: Path, split: str) -> Sequence:
    """A test sequence: every frame, frame 1's box (or one per frame, should a copy have them)."""
    return held_out_sequence(name, folder, "%08d.jpg", 1, folder / "groundtruth.txt", f"got10k_{split}",
                             f"GOT-10k {name}")


def _loader(split: str) -> Callable[..., list[Sequence]]:
    load_one = _first_box_only if split == "test" else _annotated

    def load(root, sequences=None) -> list[Sequence]:
        folder = split_folder(root, split)
        available = sorted(p.name for p in folder.iterdir() if listed(p / "groundtruth.txt"))
        return [load_one(name, folder / name, split)
                for name in select_sequences(available, sequences, f"GOT-10k {split} at {folder}")]
    load.__doc__ = f"GOT-10k's {split} split: ``ROOT/{split}/<seq>/%08d.jpg``, ``groundtruth.txt``."
    return load


def _detector(split: str) -> Callable[[Path], Evidence]:
    def detect(root: Path) -> Evidence:
        folder = _find_split(root, split)
        if folder is None or not (folder / "list.txt").is_file():
            return Evidence.NONE
        return Evidence.NAME if any(folder.glob("GOT-10k_*/groundtruth.txt")) else Evidence.NONE
    return detect


got10k_train = _loader("train")
got10k_val = _loader("val")
got10k_test = _loader("test")


def _description(split: str) -> str:
    labels = "frame 1's box only: scored by the server" if split == "test" else "cover.label, absence.label"
    return (f"ROOT/{split}/<GOT-10k_{split.capitalize()}_NNNNNN>/%08d.jpg, groundtruth.txt ({labels}), "
            f"ROOT/{split}/list.txt")


register_layout("got10k_train", got10k_train, _description("train"), detect=_detector("train"),
                protocol="got10k")
register_layout("got10k_val", got10k_val, _description("val"), detect=_detector("val"),
                protocol="got10k")
register_layout("got10k_test", got10k_test, _description("test"), detect=_detector("test"),
                protocol="got10k")
