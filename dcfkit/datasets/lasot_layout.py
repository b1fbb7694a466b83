"""LaSOT and its extension subset: ``ROOT/<class>/<class>-<n>/`` (or, as pysot keeps it, flat
``ROOT/<class>-<n>/``) holding ``img/%08d.jpg``, ``groundtruth.txt`` (``x,y,w,h`` a line,
1-based), ``full_occlusion.txt`` and ``out_of_view.txt`` (one line of 0/1 flags, one a frame)
and ``nlp.txt``.

A frame whose full-occlusion or out-of-view flag is 1 is *absent*: its row is NaN, whatever
box the file holds there (the toolkits go by the flags: the LaSOT toolkit's ``absent``
annotations, pytracking's ``target_visible``, pysot's ``absent``). The frames are
``img/00000001.jpg`` to the annotation's length; images beyond it are left out (monkey-17
holds more images than annotated frames, and the toolkits score the annotated ones).
Attributes come from the LaSOT evaluation toolkit's ``annos/att/<seq>.txt`` files when that
folder is copied or linked to ``ROOT/annos/att``: 14 comma-separated flags in the order of
:data:`LASOT_ATTRIBUTES`. ``lasot_test`` loads the sequences ``ROOT/testing_set.txt`` lists
(protocol II of the LaSOT paper: 280 sequences; the file comes with the benchmark and the toolkit).
"""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from dcfkit.datasets.annotations import listed, read_boxes, read_flags, read_frame_values, read_text
from dcfkit.datasets.base import DatasetError, Sequence, numbered_frames, require_root, select_sequences
from dcfkit.datasets.layout import Evidence, register_layout

#: Column order of the toolkit's att files (``att_fig_name`` of run_tracker_performance_evaluation.m).
LASOT_ATTRIBUTES = ("IV", "POC", "DEF", "MB", "CM", "ROT", "BC", "VC", "SV", "FOC", "FM", "OV", "LR", "ARC")
ABSENCE_FILES = ("full_occlusion.txt", "out_of_view.txt")
SPLIT_FILE = "testing_set.txt"
_SEQUENCE_NAME = re.compile(r"^(.+)-(\d+)$")  # <class>-<n>


def _is_sequence(folder: Path) -> bool:
    return _SEQUENCE_NAME.match(folder.name) is not None and listed(folder / "groundtruth.txt")


def _class_members(folder: Path) -> list[Path]:
    """The sequence folders ``<class>-<n>`` of a class folder (none if it is not one)."""
    return [p for p in sorted(folder.iterdir()) if p.name.startswith(folder.name + "-") and _is_sequence(p)]


def sequence_folders(root: Path) -> dict[str, Path]:
    """Sequence name -> folder, nested (``<class>/<class>-<n>``) or flat (``<class>-<n>``), in
    class then number order."""
    found: dict[str, Path] = {}
    for child in sorted(p for p in root.iterdir() if p.is_dir()):
        for folder in [child] if _is_sequence(child) else _class_members(child):
            if folder.name in found:
                raise DatasetError(f"LaSOT: sequence {folder.name!r} is both {found[folder.name]} and {folder}")
            found[folder.name] = folder
    return dict(sorted(found.items(), key=lambda item: _order(item[0])))


def _order(name: str) -> tuple[str, int]:
    cls, number = _SEQUENCE_NAME.match(name).groups()
    return cls, int(number)


def absent_frames(folder: Path, n_frames: int) -> np.ndarray:
    """``(n_frames,) bool``: the frames whose full-occlusion or out-of-view flag is 1."""
    absent = np.zeros(n_frames, dtype=bool)
    for name in ABSENCE_FILES:
        flags = read_frame_values(folder / name, n_frames)
        if not np.isin(flags, (0, 1)).all():
            bad = int(np.flatnonzero(~np.isin(flags, (0, 1)))[0])
            raise DatasetError(f"{folder / name}: frame {bad + 1} is flagged {flags[bad]}; flags are 0 or 1")
        absent |= flags == 1
    return absent


def _attributes(att_dir: Path, name: str) -> dict[str, bool]:
    att_file = att_dir / f"{name}.txt"
    return read_flags(att_file, LASOT_ATTRIBUTES) if att_file.is_file() else {}


def _load_sequence(name: str, folder: Path, att_dir: Path, dataset: str) -> Sequence:
    anno = folder / "groundtruth.txt"
    boxes = read_boxes(anno)
    boxes[absent_frames(folder, len(boxes))] = np.nan
    frames = numbered_frames(folder / "img", "%08d.jpg", 1, len(boxes), f"LaSOT {name}")
    return Sequence(name, frames, boxes, _attributes(att_dir, name), dataset, anno)


def _listed(root: Path, folders: dict[str, Path]) -> list[str]:
    """The sequences of ``ROOT/testing_set.txt``, all of which must be present."""
    split = root / SPLIT_FILE
    if not split.is_file():
        raise DatasetError(f"LaSOT test split: {split} not found; copy the benchmark's {SPLIT_FILE} (also in the "
                           f"LaSOT toolkit's sequence_evaluation_config/) there, or load all sequences as 'lasot'")
    listed = [line.strip() for line in read_text(split).splitlines() if line.strip()]
    missing = [name for name in listed if name not in folders]
    if missing:
        raise DatasetError(f"{split} lists {len(missing)} sequences not under {root}: {', '.join(missing[:10])}"
                           f"{' ...' if len(missing) > 10 else ''}")
    return listed


def _load(root, sequences, dataset: str, split: bool) -> list[Sequence]:
    root = require_root(root, "LaSOT")
    folders = sequence_folders(root)
    available = _listed(root, folders) if split else list(folders)
    att_dir = root / "annos" / "att"
    return [_load_sequence(name, folders[name], att_dir, dataset)
            for name in select_sequences(available, sequences, f"{dataset} at {root}")]


def lasot(root, sequences=None) -> list[Sequence]:
    """Every LaSOT sequence under ``root`` (nested or flat layout; the extension subset too)."""
    return _load(root, sequences, "lasot", split=False)


def lasot_test(root, sequences=None) -> list[Sequence]:
    """The sequences of ``ROOT/testing_set.txt`` (LaSOT's test split, protocol II)."""
    return _load(root, sequences, "lasot_test", split=True)


def _sample(root: Path, n: int = 5) -> list[Path]:
    """Up to ``n`` sequence folders: flat ones, or the first of each class folder."""
    sample = []
    for child in sorted(p for p in root.iterdir() if p.is_dir()):
        if _is_sequence(child):
            sample.append(child)
        elif _SEQUENCE_NAME.match(child.name) is None:
            sample += _class_members(child)[:1]
        if len(sample) >= n:
            break
    return sample


def detect_lasot(root: Path) -> Evidence:
    """Sequence folders named ``<class>-<n>`` with LaSOT's absence files; or, by the root's
    name, with ``groundtruth.txt`` and ``img/`` alone."""
    sample = [p for p in _sample(root) if (p / "img").is_dir()]
    if not sample:
        return Evidence.NONE
    if "lasot" in root.name.lower():
        return Evidence.NAME
    with_flags = all((p / f).is_file() for p in sample for f in ABSENCE_FILES)
    return Evidence.FILES if with_flags else Evidence.NONE


register_layout("lasot", lasot, "ROOT/<class>/<class>-<n>/img/%08d.jpg (or flat ROOT/<class>-<n>/), "
                "groundtruth.txt, full_occlusion.txt, out_of_view.txt beside img/",
                detect=detect_lasot, aliases=("lasot_extension", "lasot_ext"), protocol="lasot")
register_layout("lasot_test", lasot_test, "the sequences of ROOT/testing_set.txt (LaSOT's 280 test sequences) "
                "in lasot's layout", protocol="lasot")
