"""DTB70: ``ROOT/<seq>/img/%05d.jpg`` and ``ROOT/<seq>/groundtruth_rect.txt``."""
from __future__ import annotations

from pathlib import Path

from dcfkit.datasets.annotations import listed, read_boxes
from dcfkit.datasets.base import (
    Sequence,
    annotated_frames,
    first_frame_digits,
    image_sequence_folders,
    require_root,
    select_sequences,
)
from dcfkit.datasets.layout import Evidence, register_layout


def dtb70(root, sequences=None) -> list[Sequence]:
    """DTB70: ``ROOT/<seq>/img/%05d.jpg`` and ``ROOT/<seq>/groundtruth_rect.txt``."""
    root = require_root(root, "DTB70")
    available = sorted(p.name for p in root.iterdir() if listed(p / "groundtruth_rect.txt"))
    out = []
    for name in select_sequences(available, sequences, f"DTB70 at {root}"):
        anno = root / name / "groundtruth_rect.txt"
        boxes = read_boxes(anno)
        frames = annotated_frames(root / name / "img", "%05d.jpg", boxes, anno, f"DTB70 {name}")
        out.append(Sequence(name, frames, boxes, {}, "dtb70", anno))
    return out


def detect_dtb70(root: Path) -> Evidence:
    """OTB's layout too, so told apart by the root's name, else by 5-digit frame names. A root
    with other frame names is not DTB70's, whatever its name: its loader reads ``%05d.jpg``
    only (OTB's reads any, so a mixed set is OTB's)."""
    folders = image_sequence_folders(root)
    digits = first_frame_digits(folders)
    if not folders or digits - {5}:
        return Evidence.NONE
    if "dtb" in root.name.lower():
        return Evidence.NAME
    return Evidence.FILES if digits == {5} else Evidence.FOLDERS


register_layout("dtb70", dtb70, "ROOT/<seq>/img/%05d.jpg, ROOT/<seq>/groundtruth_rect.txt",
                detect=detect_dtb70)
