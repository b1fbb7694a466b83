"""OTB-2013/2015 (OTB50, OTB100): ``ROOT/<seq>/img/*.jpg`` and ``ROOT/<seq>/groundtruth_rect.txt``,
or ``groundtruth_rect.1.txt``, ``.2.txt`` … for the sequences with several targets.

Attributes (dcfkit ships none) come from the user's copy of either the OTB toolkit's
``anno/att/<seq>.txt`` files, copied or linked to ``ROOT/anno/att/`` (11 flags in the order of
:data:`OTB_ATTRIBUTES`), or pysot's ``OTB100.json`` in ROOT (each sequence's ``attr`` list);
an att file wins over the JSON, and a sequence in neither has none.
"""
from __future__ import annotations

import json
import os
import re
from pathlib import Path

import numpy as np

from dcfkit.datasets.annotations import listed, read_boxes, read_flags, read_text
from dcfkit.datasets.base import (
    DatasetError,
    Sequence,
    check_box_count,
    first_frame_digits,
    image_sequence_folders,
    require_root,
    select_sequences,
)
from dcfkit.datasets.layout import Evidence, register_layout
from dcfkit.errors import shown

#: Column order of the OTB toolkit's att files (``attName`` of its perfPlot.m).
OTB_ATTRIBUTES = ("IV", "OPR", "SV", "OCC", "DEF", "MB", "FM", "IPR", "OV", "BC", "LR")
PYSOT_JSON = "OTB100.json"

# OTB sequences whose image folder holds more frames than are annotated (as in the
# got10k and pysot toolkits): name -> first and last image number used.
_TOOLKIT_FRAME_RANGES = {
    "David": (300, 770),
    "Football1": (1, 74),
    "Freeman3": (1, 460),
    "Freeman4": (1, 283),
    "Diving": (1, 215),
}


_TARGET_FILE = re.compile(r"groundtruth_rect\.([0-9]+)\.txt")  # one target of a multi-target folder


def _targets(root: Path) -> dict[str, Path]:
    """Sequence name -> annotation file; multi-target folders give ``Name-1``, ``Name-2``."""
    targets: dict[str, Path] = {}

    def add(name: str, annotation: Path) -> None:
        if name in targets:
            raise DatasetError(f"two targets are named {name!r}: {targets[name]} and {annotation}; rename one")
        targets[name] = annotation

    for folder in sorted(p for p in root.iterdir() if p.is_dir()):
        if listed(folder / "groundtruth_rect.txt"):
            add(folder.name, folder / "groundtruth_rect.txt")
            continue
        numbered = sorted(
            (p for p in folder.glob("groundtruth_rect.*.txt")
             if _TARGET_FILE.fullmatch(p.name) and read_text(p).strip()),  # OTB-100 has empty ones
            key=lambda p: int(_TARGET_FILE.fullmatch(p.name).group(1)))
        if len(numbered) == 1:
            add(folder.name, numbered[0])
        else:
            for p in numbered:
                add(f"{folder.name}-{_TARGET_FILE.fullmatch(p.name).group(1)}", p)
    return targets


def _numbered_jpgs(img: Path, name: str) -> dict[int, Path]:
    """Frame number -> file of the ``.jpg`` files named by a number (``0001.jpg``, ``1.jpg``)."""
    numbered: dict[int, Path] = {}
    for f in os.listdir(img):
        stem, ext = os.path.splitext(f)
        if ext.lower() == ".jpg" and stem.isdigit():
            if int(stem) in numbered:
                raise DatasetError(f"OTB {name}: {numbered[int(stem)].name} and {f} in {img} are both "
                                   f"frame {int(stem)}")
            numbered[int(stem)] = img / f
    return numbered


def _frames(name: str, anno: Path, boxes: np.ndarray) -> tuple[Path, ...]:
    """The annotated frames: the toolkit's range, else as many as there are boxes, from the first."""
    img = anno.parent / "img"
    if not img.is_dir():
        raise DatasetError(f"OTB {name}: image folder not found: {img}")
    numbered = _numbered_jpgs(img, name)
    if anno.parent.name in _TOOLKIT_FRAME_RANGES:
        first, last = _TOOLKIT_FRAME_RANGES[anno.parent.name]
        check_box_count(boxes, last - first + 1, anno, f"frames {first}..{last}, as in the OTB toolkit")
    else:
        check_box_count(boxes, len(numbered), anno, f"{len(numbered)} numbered .jpg files in {img}")
        first = min(numbered, default=1)
        last = first + len(boxes) - 1
    missing = [k for k in range(first, last + 1) if k not in numbered]
    if missing:
        raise DatasetError(
            f"OTB {name}: frames {missing[:3]}{' ...' if len(missing) > 3 else ''} "
            f"missing in {img} (expected frames {first}..{last})")
    return tuple(numbered[k] for k in range(first, last + 1))


def _pysot_attributes(path: Path) -> dict[str, dict[str, bool]]:
    """Sequence name (lower case) -> attributes, from pysot's JSON (``{seq: {"attr": [...]}}``)."""
    try:
        table = json.loads(read_text(path))
    except json.JSONDecodeError as exc:
        raise DatasetError(f"{path}, line {exc.lineno}: not JSON ({exc.msg})") from None
    if not isinstance(table, dict):
        raise DatasetError(f"{path}: expected an object of sequences, got a {type(table).__name__}")
    out = {}
    for name, entry in table.items():
        attrs = entry.get("attr") if isinstance(entry, dict) else None
        if not isinstance(attrs, list) or not set(attrs) <= set(OTB_ATTRIBUTES):
            raise DatasetError(f"{path}: sequence {name!r}: 'attr' must be a list of {', '.join(OTB_ATTRIBUTES)}, "
                               f"got {shown(attrs)}")
        out[name.lower()] = {a: a in attrs for a in OTB_ATTRIBUTES}
    return out


def _attribute_source(root: Path):
    """``attributes(name) -> dict``: the toolkit's att file, else pysot's JSON entry, else none."""
    att_dir = root / "anno" / "att"
    att_files = {p.stem.lower(): p for p in att_dir.glob("*.txt")} if att_dir.is_dir() else {}
    from_json = _pysot_attributes(root / PYSOT_JSON) if (root / PYSOT_JSON).is_file() else {}

    def attributes(name: str) -> dict[str, bool]:
        att_file = att_files.get(name.lower())
        return read_flags(att_file, OTB_ATTRIBUTES) if att_file else from_json.get(name.lower(), {})
    return attributes


def otb(root, sequences=None) -> list[Sequence]:
    """OTB-2013/2015: ``ROOT/<seq>/img/*.jpg`` and ``ROOT/<seq>/groundtruth_rect.txt``.

    Multi-target sequences (``groundtruth_rect.1.txt`` …) are named ``Jogging-1`` etc.;
    David, Football1, Freeman3, Freeman4 and Diving use the frame ranges of the OTB toolkit.
    Attributes as the module says.
    """
    root = require_root(root, "OTB")
    targets = _targets(root)
    chosen = select_sequences(sorted(targets), sequences, f"OTB at {root}")
    attributes = _attribute_source(root)
    out = []
    for name in chosen:
        anno = targets[name]
        boxes = read_boxes(anno)
        out.append(Sequence(name, _frames(name, anno, boxes), boxes, attributes(name), "otb", anno))
    return out


def detect_otb(root: Path) -> Evidence:
    """DTB70's layout too, so told apart by the root's name, else by 4-digit frame names."""
    folders = image_sequence_folders(root)
    if not folders:
        return Evidence.NONE
    if any(hint in root.name.lower() for hint in ("otb", "tb100", "tb50")):
        return Evidence.NAME
    return Evidence.FILES if first_frame_digits(folders) == {4} else Evidence.FOLDERS


register_layout("otb", otb, "ROOT/<seq>/img/*.jpg, ROOT/<seq>/groundtruth_rect.txt (or .1.txt, .2.txt ...)",
                detect=detect_otb, aliases=("otb100", "otb2015", "otb2013", "otb50"))
