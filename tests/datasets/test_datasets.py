"""Loaders on small fixture folders (every layout and variant, error cases) and on the
real development data in ../shared/data (skipped when absent)."""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import cv2
import numpy as np
import pytest

from dcfkit import datasets
from dcfkit.datasets import (
    DatasetError,
    DatasetWarning,
    Evidence,
    Sequence,
    canonical_name,
    detect_dataset,
    layouts,
    load_dataset,
    read_boxes,
    read_frame,
    register_layout,
    registered_layout,
)
from dcfkit.datasets.base import numbered_frames, require_root, select_sequences
from dcfkit.datasets.uav123_layout import uav123_sequence_table
from dcfkit.errors import RegistryError

# --------------------------------------------------------------------------- fixture builders


def write_jpg(path: Path, value: int = 0) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    assert cv2.imwrite(str(path), np.full((8, 8, 3), value, np.uint8))


def touch_frames(folder: Path, pattern: str, first: int, last: int, real: int = 2) -> None:
    """Empty placeholder frames (the loaders only check existence) plus ``real`` real jpgs."""
    folder.mkdir(parents=True, exist_ok=True)
    for k in range(first, last + 1):
        if k < first + real:
            write_jpg(folder / (pattern % k), value=k)
        else:
            (folder / (pattern % k)).touch()


def write_anno(path: Path, n: int, sep: str = ",", nan_rows=()) -> np.ndarray:
    """n 1-based boxes; returns them 0-based."""
    path.parent.mkdir(parents=True, exist_ok=True)
    rows = np.array([[10 + k, 20 + 2 * k, 30, 40] for k in range(n)], dtype=float)
    lines = [sep.join(f"{v:g}" for v in r) for r in rows]
    for i in nan_rows:
        lines[i] = sep.join(["NaN"] * 4)
        rows[i] = np.nan
    path.write_text("\n".join(lines) + "\n")
    return rows - [1, 1, 0, 0]


def uav_root(tmp_path: Path, subset="UAV123_10fps", nested=True, seqs=("wakeboard7",),
             anno_subset=None, data_subset=None) -> Path:
    """A UAV123-family root holding ``seqs`` with the frame ranges of the official table."""
    root = tmp_path / subset
    table = uav123_sequence_table()[subset]
    anno = root / "anno" / (anno_subset or subset) if nested else root / "anno"
    data = root / "data_seq" / (data_subset or subset) if nested else root / "data_seq"
    for name in seqs:
        folder, first, last = table[name]
        write_anno(anno / f"{name}.txt", last - first + 1)
        touch_frames(data / folder, "%06d.jpg", first, last)
    return root


# --------------------------------------------------------------------------- annotation parsing


def test_read_boxes_separators_nan_and_one_based(tmp_path):
    p = tmp_path / "gt.txt"
    p.write_text("1,2,3,4\n5\t6\t7\t8\n9 10  11 12\nNaN,NaN,NaN,NaN\r\n13, 14, 15, 16\n\n\n")
    boxes = read_boxes(p)
    assert boxes.dtype == np.float64 and boxes.shape == (5, 4)
    np.testing.assert_array_equal(boxes[0], [0, 1, 3, 4])
    np.testing.assert_array_equal(boxes[2], [8, 9, 11, 12])
    assert np.isnan(boxes[3]).all()
    np.testing.assert_array_equal(read_boxes(p, one_based=False)[4], [13, 14, 15, 16])


@pytest.mark.parametrize("bad", ["1,2,3", "1,2,3,x", "", "1,2,3,4,5"])
def test_read_boxes_malformed_line_names_file_and_line(tmp_path, bad):
    p = tmp_path / "gt.txt"
    p.write_text(f"1,2,3,4\n{bad}\n5,6,7,8\n")
    with pytest.raises(DatasetError, match=r"gt\.txt, line 2"):
        read_boxes(p)


# --------------------------------------------------------------------------- UAV123 family


def test_uav123_10fps_nested_layout(tmp_path):
    root = uav_root(tmp_path, seqs=("wakeboard7", "truck4_1", "truck4_2"))
    seqs = load_dataset("UAV123@10fps", root)
    assert [s.name for s in seqs] == ["truck4_1", "truck4_2", "wakeboard7"]  # table order
    t1, t2, wb = seqs
    assert len(t1) == 193 and len(t2) == 229 and len(wb) == 67
    # truck4_2 uses frames 193..421 of folder truck4
    assert t2.frames[0].name == "000193.jpg" and t2.frames[-1].name == "000421.jpg"
    assert t2.frames[0].parent.name == "truck4"
    assert wb.dataset == "uav123_10fps"
    np.testing.assert_array_equal(wb.ground_truth[0], [9, 19, 30, 40])
    # attributes come from the packaged table when there is no att file
    assert wb.attributes["SV"] and wb.attributes["ARC"] and not wb.attributes["FOC"]
    assert list(wb.attributes) == ["SV", "ARC", "LR", "FM", "FOC", "POC", "OV", "BC", "IV", "VC", "CM", "SOB"]
    assert wb.frame(0).shape == (8, 8, 3)
    assert wb.annotation == root / "anno" / "UAV123_10fps" / "wakeboard7.txt"


def test_uav_att_file_takes_precedence(tmp_path):
    root = uav_root(tmp_path)
    att = root / "anno" / "UAV123_10fps" / "att" / "wakeboard7.txt"
    att.parent.mkdir()
    att.write_text("0,0,0,0,1,0,0,0,0,0,0,1\n")
    (seq,) = load_dataset("uav123_10fps", root)
    assert {k for k, v in seq.attributes.items() if v} == {"FOC", "SOB"}
    att.write_text("0,1,0\n")
    with pytest.raises(DatasetError, match="wakeboard7.txt"):
        load_dataset("uav123_10fps", root)


def test_uav123_flat_variant(tmp_path):
    root = uav_root(tmp_path, nested=False, seqs=("wakeboard7",))
    assert (root / "anno" / "wakeboard7.txt").is_file()
    (seq,) = load_dataset("uav123_10fps", root)
    assert len(seq) == 67 and seq.frames[0].parent == root / "data_seq" / "wakeboard7"
    assert detect_dataset(root) == "uav123_10fps"  # decided by the annotation length


def test_uav123_30fps_subset(tmp_path):
    root = uav_root(tmp_path, subset="UAV123", seqs=("wakeboard7",))
    (seq,) = load_dataset("uav123", root)
    assert len(seq) == 199 and seq.dataset == "uav123"
    assert detect_dataset(root) == "uav123"


def test_uav20l_official_layout_and_attributes(tmp_path):
    # official release: anno/UAV20L/<seq>.txt with the images of data_seq/UAV123/
    root = uav_root(tmp_path, subset="UAV123_20L", seqs=("bike1", "car1"),
                    anno_subset="UAV20L", data_subset="UAV123")
    bike1, car1 = load_dataset("uav20l", root)
    assert len(bike1) == 3085 and len(car1) == 2629
    assert bike1.attributes and bike1.attributes["SV"]  # same frames as UAV123 bike1
    assert car1.attributes == {}  # UAV123 has car1_1..3, not car1: no packaged attributes
    assert detect_dataset(root) == "uav123_20l"


def test_uav_listing_only_present_sequences_and_not_found(tmp_path):
    root = uav_root(tmp_path, seqs=("wakeboard7", "truck4_1"))
    with pytest.raises(DatasetError) as e:
        load_dataset("uav123_10fps", root, ["wakeboard"])
    msg = str(e.value)
    assert "'wakeboard'" in msg and "Did you mean 'wakeboard7'" in msg and "truck4_1" in msg
    assert [s.name for s in load_dataset("uav123_10fps", root, "WAKEBOARD7")] == ["wakeboard7"]
    # each sequence once, however often it is named, and the repeat said
    with pytest.warns(DatasetWarning, match="'wakeboard7' listed more than once: each sequence counts once"):
        assert [s.name for s in load_dataset("uav123_10fps", root, "wakeboard7,truck4_1,Wakeboard7")] == \
            ["wakeboard7", "truck4_1"]
    # a sequence of the benchmark whose annotation file is missing: that file is named
    # and the sequences that are there are listed
    with pytest.raises(DatasetError, match=r"sequence 'boat1' .*annotation file not found: .*boat1\.txt\. "
                                           r"Available \(2\): truck4_1, wakeboard7"):
        load_dataset("uav123_10fps", root, ["boat1"])


def test_a_root_without_sequences_of_the_dataset_is_an_error(tmp_path):
    root = uav_root(tmp_path)
    with pytest.raises(DatasetError, match=r"no dtb70 sequences under .*UAV123_10fps; expected ROOT/<seq>/img"):
        load_dataset("dtb70", root)
    for empty in ("", ",", []):
        with pytest.raises(DatasetError, match=r"no sequence names given for UAV123_10fps at"):
            load_dataset("uav123_10fps", root, empty)


def test_annotation_that_is_not_text_names_the_file(tmp_path):
    path = tmp_path / "gt.txt"
    path.write_bytes(b"1,2,3,4\n5,6,7,8\xe9\n")
    with pytest.raises(DatasetError, match=r"gt\.txt: not a text annotation file \(byte 15"):
        read_boxes(path)


def test_other_text_files_that_are_not_utf8_name_the_file(tmp_path):
    root = uav_root(tmp_path)
    att = root / "anno" / "UAV123_10fps" / "att" / "wakeboard7.txt"
    att.parent.mkdir()
    att.write_bytes(b"0,1,0,1,0,0,0,0,0,0,1,0\xe9\n")  # a UnicodeDecodeError traceback before
    with pytest.raises(DatasetError, match=r"att.wakeboard7.txt: not a text annotation file \(byte 23"):
        load_dataset("uav123_10fps", root)
    att.write_text("\ufeff1,1,0,0,0,0,0,0,0,0,0,0\n")  # a BOM, as annotation files may have
    (seq,) = load_dataset("uav123_10fps", root)
    assert seq.attributes["SV"] and seq.attributes["ARC"] and not seq.attributes["LR"]


def test_uav_missing_folder_missing_frames_and_count(tmp_path):
    root = uav_root(tmp_path)
    frames = root / "data_seq" / "UAV123_10fps" / "wakeboard7"
    (frames / "000033.jpg").unlink()
    with pytest.raises(DatasetError, match=r"missing .*000033\.jpg"):
        load_dataset("uav123_10fps", root)
    for f in frames.iterdir():
        f.unlink()
    frames.rmdir()
    with pytest.raises(DatasetError, match="image folder not found.*wakeboard7"):
        load_dataset("uav123_10fps", root)
    root = uav_root(tmp_path / "b")
    anno = root / "anno" / "UAV123_10fps" / "wakeboard7.txt"
    anno.write_text(anno.read_text() + "1,1,1,1\n")
    with pytest.raises(DatasetError, match=r"wakeboard7\.txt: 68 annotation lines but 67 frames"):
        load_dataset("uav123_10fps", root)
    with pytest.raises(DatasetError, match="folder not found"):
        load_dataset("uav123", tmp_path / "nowhere")


# --------------------------------------------------------------------------- DTB70, UAVDT, OTB


def dtb_root(tmp_path, n=5, nan_rows=()):
    root = tmp_path / "DTB70"
    gt = write_anno(root / "Gull1" / "groundtruth_rect.txt", n, nan_rows=nan_rows)
    touch_frames(root / "Gull1" / "img", "%05d.jpg", 1, n, real=n)
    write_anno(root / "Car2" / "groundtruth_rect.txt", 3)
    touch_frames(root / "Car2" / "img", "%05d.jpg", 1, 3)
    return root, gt


def test_dtb70(tmp_path):
    root, gt = dtb_root(tmp_path, nan_rows=(2,))
    seqs = load_dataset("DTB70", root)
    assert [s.name for s in seqs] == ["Car2", "Gull1"]
    gull = seqs[1]
    assert isinstance(gull, Sequence) and len(gull) == 5 and gull.attributes == {}
    np.testing.assert_array_equal(gull.ground_truth, gt)  # NaN row kept
    assert np.isnan(gull.ground_truth[2]).all()
    assert not gull.ground_truth.flags.writeable
    assert gull.frame(4)[0, 0, 0] in (4, 5, 6)  # jpeg of value 5
    assert detect_dataset(root) == "dtb70"
    assert gull.annotation == root / "Gull1" / "groundtruth_rect.txt"
    (root / "Gull1" / "img" / "00006.jpg").touch()
    with pytest.raises(DatasetError, match="5 annotation lines but 6 frames"):
        load_dataset("dtb70", root, ["Gull1"])
    (root / "Gull1" / "img" / "00006.jpg").unlink()
    anno = root / "Gull1" / "groundtruth_rect.txt"
    anno.write_text(anno.read_text() + "1,1,1,1\n")
    with pytest.raises(DatasetError, match=r"groundtruth_rect\.txt: 6 annotation lines but 5 \.jpg files .*"
                                           r"extra lines or frames 00006\.jpg\.\.00006\.jpg are missing"):
        load_dataset("dtb70", root, ["Gull1"])


def test_unreadable_frame_names_the_file(tmp_path):
    root, _ = dtb_root(tmp_path)
    (root / "Car2" / "img" / "00003.jpg").write_bytes(b"not a jpeg")
    (seq,) = load_dataset("dtb70", root, ["Car2"])
    with pytest.raises(DatasetError, match=r"frame 3 of sequence 'Car2'.*00003\.jpg"):  # numbered from 1
        seq.frame(2)


def test_truncated_jpeg_is_refused_and_complete_ones_are_not(tmp_path):
    rng = np.random.default_rng(0)
    image = rng.integers(0, 255, (64, 80, 3), np.uint8)
    ok, jpeg = cv2.imencode(".jpg", image)
    data = jpeg.tobytes()
    names = ("good", "padded", "no_end", "cut", "missing")
    good, padded, no_end, cut, missing = (tmp_path / f"{n}.jpg" for n in names)
    good.write_bytes(data)
    padded.write_bytes(data + b"\x00" * 16)
    no_end.write_bytes(data[:-2])  # only the end-of-image marker is missing: read as imread does
    cut.write_bytes(data[: len(data) * 2 // 3])
    assert read_frame(good).shape == (64, 80, 3)
    np.testing.assert_array_equal(read_frame(padded), read_frame(good))
    np.testing.assert_array_equal(read_frame(no_end), read_frame(good))
    with pytest.raises(DatasetError, match=r"cannot read frame 7: .*cut\.jpg \(truncated JPEG"):
        read_frame(cut, "frame 7")
    with pytest.raises(DatasetError, match=r"missing\.jpg \(file does not exist\)"):
        read_frame(missing)
    with pytest.raises(DatasetError, match=r"not a regular file"):
        read_frame(tmp_path)


def test_uavdt(tmp_path):
    root = tmp_path / "UAVDT"
    gt = write_anno(root / "anno" / "S0601_gt.txt", 4)
    touch_frames(root / "data_seq" / "S0601", "img%06d.jpg", 1, 4)
    (root / "anno" / "S0601_att.txt").write_text("1,0,0,1,0,0,0,0\n")  # not a sequence
    (seq,) = load_dataset("uavdt", root)
    assert seq.name == "S0601" and seq.frames[-1].name == "img000004.jpg"
    np.testing.assert_array_equal(seq.ground_truth, gt)
    assert seq.annotation == root / "anno" / "S0601_gt.txt"
    assert detect_dataset(root) == "uavdt"
    (root / "data_seq" / "S0601" / "img000004.jpg").unlink()
    with pytest.raises(DatasetError, match="img000004.jpg"):
        load_dataset("uavdt", root)


def test_otb_separators_multi_target_and_frame_ranges(tmp_path):
    root = tmp_path / "OTB100"
    gt = write_anno(root / "Basketball" / "groundtruth_rect.txt", 4, sep="\t")
    touch_frames(root / "Basketball" / "img", "%04d.jpg", 1, 4)
    write_anno(root / "Jogging" / "groundtruth_rect.1.txt", 3, sep=" ")
    write_anno(root / "Jogging" / "groundtruth_rect.2.txt", 3, sep=",")
    touch_frames(root / "Jogging" / "img", "%04d.jpg", 1, 3)
    (root / "Human4").mkdir()
    (root / "Human4" / "groundtruth_rect.1.txt").write_text("")  # empty as in OTB-100
    write_anno(root / "Human4" / "groundtruth_rect.2.txt", 2)
    touch_frames(root / "Human4" / "img", "%04d.jpg", 1, 2)
    write_anno(root / "David" / "groundtruth_rect.txt", 471)  # frames 300..770 of 770
    touch_frames(root / "David" / "img", "%04d.jpg", 1, 770)
    seqs = {s.name: s for s in load_dataset("otb", root)}
    assert sorted(seqs) == ["Basketball", "David", "Human4", "Jogging-1", "Jogging-2"]
    np.testing.assert_array_equal(seqs["Basketball"].ground_truth, gt)
    assert seqs["David"].frames[0].name == "0300.jpg" and len(seqs["David"]) == 471
    assert seqs["Jogging-2"].annotation == root / "Jogging" / "groundtruth_rect.2.txt"
    assert detect_dataset(root) == "otb"
    write_anno(root / "Basketball" / "groundtruth_rect.txt", 3)
    with pytest.raises(DatasetError, match="3 annotation lines but 4 frames"):
        load_dataset("otb", root, ["Basketball"])
    write_jpg(root / "Human4" / "img" / "2.jpg")  # frame 2 twice: one of them was dropped silently
    with pytest.raises(DatasetError, match=r"OTB Human4: (0002.jpg and 2.jpg|2.jpg and 0002.jpg) .* both frame 2"):
        load_dataset("otb", root, ["Human4"])


def test_dataset_names_and_detection_errors(tmp_path):
    with pytest.raises(DatasetError, match="valid names: uav123, uav123_10fps, uav123_20l, dtb70, uavdt, otb"):
        load_dataset("vot2018", tmp_path)
    assert datasets.canonical_name("UAV123_10FPS") == "uav123_10fps"
    assert datasets.canonical_name("uav123-20l") == "uav123_20l"
    with pytest.raises(DatasetError, match="no known benchmark layout"):
        detect_dataset(tmp_path)
    root = uav_root(tmp_path, seqs=("wakeboard7",))
    (root / "anno" / "UAV123").mkdir()
    with pytest.raises(DatasetError, match=r"cannot tell which dataset .*UAV123_10fps holds: uav123, "
                                           r"uav123_10fps fit equally well .*\(uav123 or uav123_10fps\)"):
        detect_dataset(root)
    amb = tmp_path / "bench"
    write_anno(amb / "A" / "groundtruth_rect.txt", 1)
    (amb / "A" / "img").mkdir()  # no frame yet: the names tell nothing
    with pytest.raises(DatasetError, match="dtb70 or otb"):
        detect_dataset(amb)
    # a 4- or 6-digit name anywhere: DTB70's loader reads %05d.jpg only, so OTB's (a mixed set)
    touch_frames(amb / "A" / "img", "%06d.jpg", 1, 1)
    write_anno(amb / "B" / "groundtruth_rect.txt", 1)
    touch_frames(amb / "B" / "img", "%05d.jpg", 1, 1)
    assert detect_dataset(amb) == "otb"
    assert [s.name for s in load_dataset(None, amb)] == ["A", "B"]
    with pytest.raises(DatasetError, match="DTB70 A"):
        load_dataset("dtb70", amb)
    named = tmp_path / "DTB70"  # the validation set's DTB70 sequences, 6-digit names: OTB's layout
    shutil.copytree(amb / "A", named / "A")
    assert detect_dataset(named) == "otb"
    real = tmp_path / "real" / "DTB70"  # DTB70's own names, and hidden files a copy may bring
    shutil.copytree(amb / "B", real / "B")
    for hidden in (".DS_Store", "._00001.jpg"):
        (real / "B" / "img" / hidden).write_bytes(b"")
    assert detect_dataset(real) == "dtb70"


# --------------------------------------------------------------------------- real data


def test_real_uav123_10fps(shared_data):
    root = shared_data / "UAV123_10fps"
    assert detect_dataset(root) == "uav123_10fps"
    seqs = {s.name: s for s in load_dataset(None, root)}
    expected = {"boat1": 301, "building4": 263, "truck4_1": 193, "truck4_2": 229,
                "wakeboard7": 67, "wakeboard10": 157}
    assert {n: len(s) for n, s in seqs.items()} == expected
    boat1 = seqs["boat1"]
    first = np.loadtxt(root / "anno" / "UAV123_10fps" / "boat1.txt", delimiter=",")[0]
    np.testing.assert_array_equal(boat1.ground_truth[0], first - [1, 1, 0, 0])
    np.testing.assert_array_equal(boat1.ground_truth[0], [392, 327, 155, 319])
    assert boat1.frame(0).shape == (720, 1280, 3)
    assert seqs["truck4_2"].frames[0].name == "000193.jpg"
    att = (root / "anno" / "UAV123_10fps" / "att" / "boat1.txt").read_text().strip().split(",")
    assert [int(v) for v in boat1.attributes.values()] == [int(v) for v in att]


def test_real_dtb70_and_uavdt(shared_data):
    (gull,) = load_dataset(detect_dataset(shared_data / "DTB70"), shared_data / "DTB70")
    assert gull.name == "Gull1" and len(gull) == 120
    np.testing.assert_array_equal(gull.ground_truth[0], [164, 639, 77, 55])
    (s0601,) = load_dataset(detect_dataset(shared_data / "UAVDT"), shared_data / "UAVDT")
    assert s0601.name == "S0601" and len(s0601) == 82
    np.testing.assert_array_equal(s0601.ground_truth[0], [561, 125, 20, 23])
    assert s0601.frame(81).shape == (540, 1024, 3)


# --------------------------------------------------------------------------- the layout registry


def toy_loader(root, sequences=None):
    """A plugin-style loader built from the base helpers: ROOT/<seq>/boxes.txt, ROOT/<seq>/frames/%03d.jpg."""
    root = require_root(root, "toy")
    available = sorted(p.name for p in root.iterdir() if (p / "boxes.txt").is_file())
    out = []
    for name in select_sequences(available, sequences, f"toy at {root}"):
        boxes = read_boxes(root / name / "boxes.txt")
        frames = numbered_frames(root / name / "frames", "%03d.jpg", 1, len(boxes), f"toy {name}")
        out.append(Sequence(name, frames, boxes, {}, "toy", root / name / "boxes.txt"))
    return out


def toy_root(tmp_path: Path) -> Path:
    root = tmp_path / "somewhere"
    for name, n in (("ant", 3), ("bee", 2)):
        write_anno(root / name / "boxes.txt", n)
        touch_frames(root / name / "frames", "%03d.jpg", 1, n)
    (root / "TOY_LAYOUT").touch()
    return root


def is_toy(root: Path) -> bool:  # a plain bool is enough evidence when nothing else fits
    return (root / "TOY_LAYOUT").is_file()


def test_a_registered_layout_is_found_by_detection_by_name_and_by_alias(tmp_path):
    root = toy_root(tmp_path)
    before = list(datasets.DATASETS)
    with pytest.raises(DatasetError, match="no known benchmark layout"):
        detect_dataset(root)
    with registered_layout("Toy", toy_loader, "ROOT/<seq>/boxes.txt, ROOT/<seq>/frames/%03d.jpg",
                           detect=is_toy, aliases=("toy-set",)) as layout:
        assert layout.name == "toy" and layout.aliases == ("toy_set",) and layouts()[-1] is layout
        assert "toy" in datasets.DATASETS
        assert detect_dataset(root) == "toy"
        auto = load_dataset("auto", root)
        assert [(s.name, len(s), s.dataset) for s in auto] == [("ant", 3, "toy"), ("bee", 2, "toy")]
        assert [s.name for s in load_dataset(None, root, "BEE")] == ["bee"]
        assert [s.name for s in load_dataset("TOY", root)] == ["ant", "bee"]
        assert [s.name for s in load_dataset("toy_set", root)] == ["ant", "bee"]  # - and _ alike
        with pytest.raises(DatasetError, match=r"no toy sequences under .*; expected ROOT/<seq>/boxes\.txt"):
            load_dataset("toy", tmp_path)
    # gone after the block, aliases too, and the built-ins are as before
    for name in ("toy", "toy_set"):
        with pytest.raises(DatasetError, match="unknown dataset"):
            load_dataset(name, root)
    with pytest.raises(DatasetError, match="no known benchmark layout"):
        detect_dataset(root)
    assert list(datasets.DATASETS) == before and before[:6] == ["uav123", "uav123_10fps", "uav123_20l", "dtb70",
                                                                 "uavdt", "otb"]


def test_a_name_or_alias_registered_twice_is_an_error_naming_it(tmp_path):
    with pytest.raises(RegistryError, match=r"dataset layout 'otb': the name 'otb' is already registered"):
        register_layout("OTB", toy_loader, "ROOT/<seq>/boxes.txt")
    with pytest.raises(RegistryError, match=r"'uav20l' is already registered \(as a name of 'uav123_20l'\)"):
        register_layout("mine", toy_loader, "ROOT/<seq>/boxes.txt", aliases=("UAV20L",))
    with pytest.raises(RegistryError, match=r"'uav123_10fps' is already registered"):
        register_layout("uav123-10fps", toy_loader, "ROOT/<seq>/boxes.txt")  # would shadow it
    with pytest.raises(RegistryError, match="one non-empty line"):
        register_layout("mine", toy_loader, "two\nlines")
    with pytest.raises(DatasetError, match="unknown dataset 'mine'"):  # nothing was half-registered
        canonical_name("mine")
    with registered_layout("toy", toy_loader, "ROOT/<seq>/boxes.txt", aliases=("tiny",)):
        with pytest.raises(RegistryError, match=r"the name 'tiny' is already registered \(as a name of 'toy'\)"):
            register_layout("other", toy_loader, "ROOT/<seq>/boxes.txt", aliases=("tiny",))
    with registered_layout("toy", toy_loader, "ROOT/<seq>/boxes.txt", aliases=("tiny",)):  # free again
        assert canonical_name("TINY") == "toy"


def test_detection_ties_are_an_error_naming_the_candidates(tmp_path):
    root = toy_root(tmp_path)
    with registered_layout("toy", toy_loader, "ROOT/<seq>/boxes.txt", detect=is_toy), \
            registered_layout("toy2", toy_loader, "ROOT/<seq>/boxes.txt too", detect=is_toy):
        with pytest.raises(DatasetError, match=r"(?s)toy, toy2 fit equally well .*\(toy or toy2\).*\n  toy2: ROOT"):
            detect_dataset(root)
        with registered_layout("toy3", toy_loader, "by name", detect=lambda r: Evidence.NAME * is_toy(r)):
            assert detect_dataset(root) == "toy3"  # the more specific evidence wins


OO_SCRIPT = """
import sys, tempfile
assert sys.flags.optimize == 2
import dcfkit.datasets as d
assert d.otb.__doc__ is None and d.load_dataset.__doc__ is None  # docstrings really are gone
for call in (lambda: d.load_dataset("vot2018", "."), lambda: d.load_dataset("dtb70", tempfile.mkdtemp()),
             lambda: d.detect_dataset(tempfile.mkdtemp())):
    try:
        call()
    except d.DatasetError as exc:
        print(exc, end="\\n@@\\n")
"""


def test_unknown_dataset_lists_the_layouts_with_descriptions_even_under_python_OO():
    with registered_layout("toy", toy_loader, "ROOT/<seq>/boxes.txt (a test's)", aliases=("tiny",)):
        with pytest.raises(DatasetError) as e:
            load_dataset("vot2018", ".")
        assert "  toy (also tiny): ROOT/<seq>/boxes.txt (a test's)" in str(e.value).splitlines()
    worktree = Path(datasets.__file__).resolve().parents[2]
    run = subprocess.run([sys.executable, "-OO", "-c", OO_SCRIPT], capture_output=True, text=True,
                         env={**os.environ, "PYTHONPATH": str(worktree)}, timeout=120)
    assert run.returncode == 0, run.stderr
    unknown, empty, undetected, _ = run.stdout.split("\n@@\n")
    assert unknown.startswith("unknown dataset 'vot2018'; valid names: uav123, uav123_10fps,")
    for layout in layouts():
        assert f"  {layout}" in unknown.splitlines() and f"  {layout}" in undetected.splitlines()
        assert layout.description in str(layout)
    assert "no dtb70 sequences under" in empty and empty.endswith("; expected ROOT/<seq>/img/%05d.jpg, "
                                                                 "ROOT/<seq>/groundtruth_rect.txt")
    assert undetected.startswith("no known benchmark layout under")
