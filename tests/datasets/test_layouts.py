"""LaSOT, GOT-10k, TrackingNet and VOT loaders, OTB attributes and dataset plugins, each on a tiny
layout built here in the benchmark's exact file formats (frames: one small JPEG, linked)."""
from __future__ import annotations

import dataclasses
import json
import os
import re
import sys
import types
import warnings
from pathlib import Path

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from dcfkit import cli
from dcfkit import registry as reg
from dcfkit.datasets import DatasetError, Sequence, benchmark_protocol, detect_dataset, load_dataset
from dcfkit.datasets.lasot_layout import LASOT_ATTRIBUTES
from dcfkit.datasets.layout import new_layout
from dcfkit.datasets.otb_layout import OTB_ATTRIBUTES
from dcfkit.datasets.vot_layout import mask_box, polygon_box, region_box
from dcfkit.errors import RegistryError

NAN = [np.nan] * 4


@pytest.fixture
def jpg(tmp_path) -> Path:
    """One 32x24 JPEG with a bright block on a textured background (KCF has something to track)."""
    rng = np.random.default_rng(0)
    image = rng.integers(0, 80, (24, 32, 3), dtype=np.uint8)
    image[6:16, 8:20] = 230
    path = tmp_path / "frame.jpg"
    assert cv2.imwrite(str(path), image)
    return path


def frames(folder: Path, names, source: Path) -> None:
    folder.mkdir(parents=True, exist_ok=True)
    for name in names:
        os.symlink(source, folder / name)


def write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


def lines(rows) -> str:
    return "".join(",".join(f"{v:g}" for v in row) + "\n" for row in rows)


# --------------------------------------------------------------------------- LaSOT


def lasot_sequence(folder: Path, jpg: Path, boxes, occluded, out_of_view, images: int | None = None) -> None:
    """A LaSOT sequence folder: groundtruth.txt, one-line flag files, nlp.txt, img/%08d.jpg."""
    write(folder / "groundtruth.txt", lines(boxes))
    write(folder / "full_occlusion.txt", ",".join(map(str, occluded)))
    write(folder / "out_of_view.txt", ",".join(map(str, out_of_view)))
    write(folder / "nlp.txt", "white airplane landing on the ground")
    frames(folder / "img", [f"{k:08d}.jpg" for k in range(1, (images or len(boxes)) + 1)], jpg)


def lasot_root(tmp_path: Path, jpg: Path, name: str = "data", flat: bool = False) -> Path:
    root = tmp_path / name
    place = (lambda seq: root / seq) if flat else (lambda seq: root / seq.split("-")[0] / seq)
    boxes = [[11, 21, 12, 10], [12, 22, 12, 10], [13, 23, 12, 10], [14, 24, 12, 10]]
    lasot_sequence(place("airplane-1"), jpg, boxes, [0, 0, 1, 0], [0, 0, 0, 1], images=5)  # one image too many
    lasot_sequence(place("airplane-10"), jpg, boxes[:3], [0, 0, 0], [0, 0, 0])
    lasot_sequence(place("airplane-2"), jpg, boxes[:2], [0, 0], [0, 0])
    lasot_sequence(place("bird-3"), jpg, boxes[:3], [0, 1, 0], [0, 0, 0])
    return root


def test_lasot_nested_layout_absent_frames_and_order(tmp_path, jpg):
    root = lasot_root(tmp_path, jpg)
    seqs = load_dataset("lasot", root)
    assert [s.name for s in seqs] == ["airplane-1", "airplane-2", "airplane-10", "bird-3"]  # class, then number
    a1 = seqs[0]
    assert a1.dataset == "lasot" and a1.annotation == root / "airplane" / "airplane-1" / "groundtruth.txt"
    np.testing.assert_array_equal(a1.ground_truth[:2], [[10, 20, 12, 10], [11, 21, 12, 10]])  # 1-based -> 0-based
    assert np.isnan(a1.ground_truth[2:]).all()  # frame 3 fully occluded, frame 4 out of view
    assert [f.name for f in a1.frames] == ["00000001.jpg", "00000002.jpg", "00000003.jpg", "00000004.jpg"]
    assert a1.attributes == {} and not a1.ground_truth_withheld  # no annos/att folder
    assert np.isnan(seqs[3].ground_truth[1]).all() and a1.frame(0).shape == (24, 32, 3)
    assert detect_dataset(root) == "lasot"
    assert [s.name for s in load_dataset("lasot-extension", root, "BIRD-3")] == ["bird-3"]


def test_lasot_flat_layout_and_attributes_of_the_toolkit(tmp_path, jpg):
    root = lasot_root(tmp_path, jpg, flat=True)
    att = root / "annos" / "att"
    write(att / "airplane-1.txt", "1,0,0,0,0,0,0,0,0,1,0,0,0,1\n")  # IV, FOC, ARC
    write(att / "bird-3.txt", "0,1,0,0,0,0,0,0,0,0,0,0,0,0\n")
    seqs = {s.name: s for s in load_dataset("lasot", root)}
    assert list(seqs["airplane-1"].attributes) == list(LASOT_ATTRIBUTES)
    assert {a for a, v in seqs["airplane-1"].attributes.items() if v} == {"IV", "FOC", "ARC"}
    assert {a for a, v in seqs["bird-3"].attributes.items() if v} == {"POC"}
    assert seqs["airplane-2"].attributes == {}  # no att file: no attributes, no error
    assert detect_dataset(root) == "lasot"
    write(att / "bird-3.txt", "0,1,0\n")
    with pytest.raises(DatasetError, match=r"bird-3\.txt, line 1: expected 14 0/1 flags"):
        load_dataset("lasot", root)


def test_lasot_test_split_is_the_testing_set_file(tmp_path, jpg):
    root = lasot_root(tmp_path, jpg)
    with pytest.raises(DatasetError, match=r"testing_set\.txt not found; copy the benchmark's testing_set\.txt"):
        load_dataset("lasot_test", root)
    write(root / "testing_set.txt", "bird-3\nairplane-1\n")
    assert [s.name for s in load_dataset("lasot_test", root)] == ["bird-3", "airplane-1"]
    assert {s.dataset for s in load_dataset("lasot_test", root)} == {"lasot_test"}
    write(root / "testing_set.txt", "bird-3\nairplane-7\n")
    with pytest.raises(DatasetError, match=r"testing_set\.txt lists 1 sequences not under .*: airplane-7"):
        load_dataset("lasot_test", root)


@pytest.mark.parametrize("file, text, message", [
    ("full_occlusion.txt", "0,0,0", r"full_occlusion\.txt: 3 values for 4 frames"),
    ("out_of_view.txt", "0,0,x,0", r"out_of_view\.txt, line 1: expected whole numbers, one per frame, got 'x' for frame 3"),
    ("out_of_view.txt", "0,2,0,0", r"out_of_view\.txt: frame 2 is flagged 2; flags are 0 or 1"),
    ("groundtruth.txt", "11,21,12,10\n11,21,12\n", r"groundtruth\.txt, line 2: expected 4 numbers"),
])
def test_lasot_malformed_files_name_the_file_and_line(tmp_path, jpg, file, text, message):
    root = lasot_root(tmp_path, jpg)
    write(root / "airplane" / "airplane-1" / file, text)
    with pytest.raises(DatasetError, match=message):
        load_dataset("lasot", root, "airplane-1")


def test_lasot_missing_frames_and_flag_files(tmp_path, jpg):
    root = lasot_root(tmp_path, jpg)
    (root / "bird" / "bird-3" / "img" / "00000002.jpg").unlink()
    with pytest.raises(DatasetError, match=r"LaSOT bird-3: 1 of frames 00000001\.jpg\.\.00000003\.jpg missing"):
        load_dataset("lasot", root, "bird-3")
    (root / "airplane" / "airplane-2" / "out_of_view.txt").unlink()
    with pytest.raises(DatasetError, match=r"annotation file not found: .*airplane-2.*out_of_view\.txt"):
        load_dataset("lasot", root, "airplane-2")


# --------------------------------------------------------------------------- GOT-10k


def got_sequence(folder: Path, jpg: Path, boxes, n_frames: int, labels: dict[str, list[int]] = ()) -> None:
    write(folder / "groundtruth.txt", lines(boxes))
    for name, values in dict(labels).items():
        write(folder / name, "".join(f"{v}\n" for v in values))
    write(folder / "meta_info.ini", "[METAINFO]\nobject_class: airplane\nresolution: (32, 24)\n")
    frames(folder, [f"{k:08d}.jpg" for k in range(1, n_frames + 1)], jpg)


def got_root(tmp_path: Path, jpg: Path, splits=("val", "test")) -> Path:
    root = tmp_path / "GOT-10k"
    boxes = [[11, 21, 12, 10], [12, 22, 12, 10], [13, 23, 12, 10]]
    if "val" in splits:
        got_sequence(root / "val" / "GOT-10k_Val_000001", jpg, boxes, 3,
                     {"cover.label": [8, 0, 5], "absence.label": [0, 1, 0], "cut_by_image.label": [0, 0, 1]})
        got_sequence(root / "val" / "GOT-10k_Val_000002", jpg, boxes, 3, {"absence.label": [0, 0, 1]})
        write(root / "val" / "list.txt", "GOT-10k_Val_000001\nGOT-10k_Val_000002\n")
    if "test" in splits:
        got_sequence(root / "test" / "GOT-10k_Test_000001", jpg, boxes[:1], 4)
        write(root / "test" / "list.txt", "GOT-10k_Test_000001\n")
    return root


def test_got10k_val_boxes_and_invisible_frames(tmp_path, jpg):
    root = got_root(tmp_path, jpg)
    for where in (root, root / "val"):  # the GOT-10k folder, or the split folder itself
        v1, v2 = load_dataset("got10k_val", where)
        assert (v1.name, v1.dataset, len(v1)) == ("GOT-10k_Val_000001", "got10k_val", 3)
        np.testing.assert_array_equal(v1.ground_truth[[0, 2]], [[10, 20, 12, 10], [12, 22, 12, 10]])  # 1-based
        assert np.isnan(v1.ground_truth[1]).all()  # cover 0
        # no cover.label: absence.label's 1
        assert np.isnan(v2.ground_truth[2]).all() and not np.isnan(v2.ground_truth[:2]).any()
        assert not v1.ground_truth_withheld and v1.attributes == {}
    assert detect_dataset(root / "val") == "got10k_val"
    assert detect_dataset(got_root(tmp_path / "only", jpg, ("val",))) == "got10k_val"
    with pytest.raises(DatasetError, match=r"got10k_val, got10k_test fit equally well .* pass the dataset name"):
        detect_dataset(root)
    with pytest.raises(DatasetError, match=r"GOT-10k train: folder not found: .*train \(it holds val, test"):
        load_dataset("got10k_train", root)


def test_got10k_test_split_has_frame_one_only_and_is_not_scored(tmp_path, jpg):
    root = got_root(tmp_path, jpg)
    (t,) = load_dataset("got10k_test", root)
    assert t.ground_truth_withheld and len(t) == 4 and t.frames[-1].name == "00000004.jpg"
    np.testing.assert_array_equal(t.ground_truth[0], [10, 20, 12, 10])
    assert np.isnan(t.ground_truth[1:]).all()
    assert detect_dataset(root / "test") == "got10k_test"
    write(t.annotation, lines([[11, 21, 12, 10]] * 2))
    with pytest.raises(DatasetError, match=r"groundtruth\.txt: 2 annotation lines but 4 frames .* frame 1's box only"):
        load_dataset("got10k_test", root)


def test_got10k_malformed_labels_name_the_file(tmp_path, jpg):
    root = got_root(tmp_path, jpg, ("val",))
    write(root / "val" / "GOT-10k_Val_000001" / "cover.label", "8\n0\n")
    with pytest.raises(DatasetError, match=r"cover\.label: 2 values for 3 frames"):
        load_dataset("got10k_val", root)
    write(root / "val" / "GOT-10k_Val_000001" / "cover.label", "8\nseven\n1\n")
    with pytest.raises(DatasetError, match=r"cover\.label, line 2: expected whole numbers"):
        load_dataset("got10k_val", root)


# --------------------------------------------------------------------------- TrackingNet


def trackingnet_root(tmp_path: Path, jpg: Path) -> Path:
    root = tmp_path / "tn"
    train = [[-3.5, 2.25, 12, 10], [1, 2, 12, 10], [2, 3, 12.5, 10]]  # as the devkit's files: may leave the image
    write(root / "TRAIN_0" / "anno" / "seqA.txt", lines(train))
    frames(root / "TRAIN_0" / "frames" / "seqA", ["0.jpg", "1.jpg", "2.jpg"], jpg)
    write(root / "TRAIN_11" / "anno" / "seqB.txt", lines(train[:2]))
    frames(root / "TRAIN_11" / "frames" / "seqB", ["0.jpg", "1.jpg"], jpg)
    write(root / "TEST" / "anno" / "seqT.txt", lines(train[:1]))
    frames(root / "TEST" / "frames" / "seqT", [f"{k}.jpg" for k in range(5)], jpg)
    return root


def test_trackingnet_chunks_zero_based_boxes_and_test_set(tmp_path, jpg):
    root = trackingnet_root(tmp_path, jpg)
    a, b = load_dataset("trackingnet_train", root)
    assert (a.name, b.name, a.dataset) == ("seqA", "seqB", "trackingnet_train")
    np.testing.assert_array_equal(a.ground_truth[0], [-3.5, 2.25, 12, 10])  # 0-based: read as it is
    assert [f.name for f in a.frames] == ["0.jpg", "1.jpg", "2.jpg"] and not a.ground_truth_withheld
    for where in (root, root / "TEST"):
        (t,) = load_dataset("trackingnet", where)
        assert t.ground_truth_withheld and len(t) == 5 and t.frames[-1].name == "4.jpg"
        assert np.isnan(t.ground_truth[1:]).all()
    assert detect_dataset(root / "TEST") == "trackingnet" and detect_dataset(root / "TRAIN_0") == "trackingnet_train"
    with pytest.raises(DatasetError, match="trackingnet, trackingnet_train fit equally well"):
        detect_dataset(root)
    (root / "TRAIN_0" / "frames" / "seqA" / "2.jpg").unlink()
    with pytest.raises(DatasetError, match=r"seqA\.txt: 3 annotation lines but 2 \.jpg files .* 2\.jpg\.\.2\.jpg"):
        load_dataset("trackingnet_train", root)


def test_trackingnet_sequence_in_two_chunks_is_an_error(tmp_path, jpg):
    root = trackingnet_root(tmp_path, jpg)
    write(root / "TRAIN_11" / "anno" / "seqA.txt", "1,2,3,4\n")
    with pytest.raises(DatasetError, match=r"sequence 'seqA' is in both .*TRAIN_0 and .*TRAIN_11"):
        load_dataset("trackingnet_train", root)


# --------------------------------------------------------------------------- VOT regions


def test_polygon_to_box_by_both_rules_against_hand_computed_boxes():
    diamond = np.array([[10, 0], [20, 10], [10, 20], [0, 10]], float)  # a square turned 45 degrees
    np.testing.assert_allclose(polygon_box(diamond, "bounds"), [0, 0, 20, 20])
    # area rule: A1 = |p1p2| |p2p3| = 200, A2 = 20 * 20 = 400, s = sqrt(1/2); w = 20 s + 1 around (10, 10)
    w = 10 * np.sqrt(2) + 1
    np.testing.assert_allclose(polygon_box(diamond, "area"), [10 - w / 2, 10 - w / 2, w, w])
    upright = np.array([[1, 2], [11, 2], [11, 7], [1, 7]], float)  # s = 1: the bounds plus 1, centred
    np.testing.assert_allclose(polygon_box(upright, "area"), [6 - 5.5, 4.5 - 3, 11, 6])
    np.testing.assert_allclose(region_box("1,2,11,2,11,7,1,7"), [1, 2, 10, 5])
    np.testing.assert_allclose(region_box("0,0,4,0,6,3,4,6,0,6,-2,3"), [-2, 0, 8, 6])  # six corners
    np.testing.assert_array_equal(region_box(" 5.5,6,7,8 "), [5.5, 6, 7, 8])
    np.testing.assert_array_equal(region_box("5.5\t6 7,8"), [5.5, 6, 7, 8])
    assert np.isnan(region_box("nan,nan,nan,nan")).all()
    with pytest.raises(ValueError, match="takes 4 corners, not 6"):
        polygon_box(np.zeros((6, 2)) + np.arange(6)[:, None], "area")


def encode_mask(mask: np.ndarray, x0: int, y0: int) -> str:
    """A VOT mask line: runs of 0s and 1s, starting with 0s, row by row (written for this test)."""
    flat = mask.ravel().astype(int)
    change = np.flatnonzero(np.diff(flat)) + 1
    runs = np.diff(np.concatenate([[0], change, [flat.size]])).tolist()
    if flat[0] == 1:
        runs = [0] + runs
    return f"m{x0},{y0},{mask.shape[1]},{mask.shape[0]}," + ",".join(map(str, runs))


@pytest.mark.parametrize("cells", [
    [(1, 2), (1, 3), (2, 2)],
    [(0, 5), (1, 0), (3, 4)],  # a run over the end of row 0 into row 1: every column
    [(4, 5)],
    [(0, 0), (0, 1), (0, 2), (0, 3), (0, 4), (0, 5), (1, 0)],
])
def test_mask_to_box_is_the_box_of_its_pixels(cells):
    mask = np.zeros((5, 6), bool)
    for r, c in cells:
        mask[r, c] = True
    rows, cols = np.nonzero(mask)
    expected = [7 + cols.min(), 3 + rows.min(), cols.max() - cols.min() + 1, rows.max() - rows.min() + 1]
    np.testing.assert_array_equal(region_box(encode_mask(mask, 7, 3)), expected)


def test_empty_and_malformed_masks():
    assert np.isnan(mask_box("3,4,5,2,10")).all()  # all zeros: no target
    assert np.isnan(mask_box("0,0,0,0")).all()
    with pytest.raises(ValueError, match="add up to 11, more than the 5x2 region holds"):
        mask_box("0,0,5,2,3,8")
    with pytest.raises(ValueError, match="negative"):
        mask_box("0,0,5,2,3,-1")


# --------------------------------------------------------------------------- VOT layout


def vot_root(tmp_path: Path, jpg: Path) -> Path:
    root = tmp_path / "workspace"
    mask = np.zeros((3, 4), bool)
    mask[1, 1:3] = True
    write(root / "ants1" / "groundtruth.txt",
          "10,5,8,6\n10,0,20,10,10,20,0,10\n" + encode_mask(mask, 2, 4)[0:] + "\nnan,nan,nan,nan\n")
    write(root / "ants1" / "sequence", "channels.color=color/%08d.jpg\nfps=30\nformat=default\nname=ants1\n")
    frames(root / "ants1" / "color", [f"{k:08d}.jpg" for k in range(1, 5)], jpg)
    write(root / "ants1" / "camera_motion.tag", "1\n0\n")  # per-frame tags: not read
    write(root / "bag" / "groundtruth.txt", "1,2,11,2,11,7,1,7\n2,2,12,2,12,7,2,7\n")  # VOT2016: frames beside it
    frames(root / "bag", ["00000001.jpg", "00000002.jpg"], jpg)
    write(root / "list.txt", "ants1\nbag\n")
    return root


def test_vot_layouts_regions_and_image_folders(tmp_path, jpg):
    root = vot_root(tmp_path, jpg)
    ants, bag = load_dataset("vot", root)
    np.testing.assert_allclose(ants.ground_truth[:3], [[10, 5, 8, 6], [0, 0, 20, 20], [3, 5, 2, 1]])  # 0-based
    assert np.isnan(ants.ground_truth[3]).all() and ants.attributes == {} and ants.dataset == "vot"
    assert ants.frames[0] == root / "ants1" / "color" / "00000001.jpg"
    assert bag.frames[1] == root / "bag" / "00000002.jpg"
    np.testing.assert_allclose(bag.ground_truth, [[1, 2, 10, 5], [2, 2, 10, 5]])
    _, bag_area = load_dataset("vot_area", root)
    np.testing.assert_allclose(bag_area.ground_truth[0], [0.5, 1.5, 11, 6])
    assert detect_dataset(root) == "vot"
    (root / "list.txt").unlink()
    assert detect_dataset(root) == "vot"  # by the folders alone, nothing else fits
    write(root / "ants1" / "sequence", "channels.color=color\n")  # a folder means %08d.jpg in it
    assert load_dataset("vot", root, "ants1")[0].frames[3].name == "00000004.jpg"
    write(root / "ants1" / "sequence", "fps=30\nname=ants1\n")  # no channel listed: the default, color/
    assert load_dataset("vot", root, "ants1")[0].frames[3] == root / "ants1" / "color" / "00000004.jpg"


@pytest.mark.parametrize("line, message", [
    ("1,2,3,4,5", r"groundtruth\.txt, line 2: expected a region .*got '1,2,3,4,5': 5 values"),
    ("1,2,x,4", r"line 2: expected a region .*could not convert"),
    ("m0,0,2,2,1,9", r"line 2: expected a region .*add up to 10, more than the 2x2 region holds"),
])
def test_vot_malformed_regions_name_file_and_line(tmp_path, jpg, line, message):
    root = vot_root(tmp_path, jpg)
    write(root / "bag" / "groundtruth.txt", f"1,2,3,4\n{line}\n")
    with pytest.raises(DatasetError, match=message):
        load_dataset("vot", root, "bag")


@pytest.mark.parametrize("channel", ["../elsewhere/%08d.jpg", "color/%s.jpg", "/abs/%08d.jpg", "c%d/%08d.jpg"])
def test_vot_sequence_file_channels_stay_inside_the_folder(tmp_path, jpg, channel):
    root = vot_root(tmp_path, jpg)
    write(root / "ants1" / "sequence", f"channels.color={channel}\n")
    with pytest.raises(DatasetError, match=r"ants1.sequence: channels.color=.* is not a frame pattern inside"):
        load_dataset("vot", root, "ants1")
    write(root / "ants1" / "sequence", "channels.depth=depth/%08d.png\n")
    with pytest.raises(DatasetError, match=r"no channels.color entry .*channels: channels.depth"):
        load_dataset("vot", root, "ants1")


def test_a_got10k_split_folder_is_not_taken_for_vot(tmp_path, jpg):
    val = got_root(tmp_path, jpg, ("val",)) / "val"
    assert detect_dataset(val) == "got10k_val"
    renamed = val.rename(tmp_path / "split")  # not named as a split: GOT-10k's files still rule VOT out
    with pytest.raises(DatasetError, match="no known benchmark layout"):
        detect_dataset(renamed)


# --------------------------------------------------------------------------- OTB attributes


def otb_root(tmp_path: Path, jpg: Path) -> Path:
    root = tmp_path / "benchmark"
    for name, gt_files in (("Basketball", ["groundtruth_rect.txt"]), ("Jogging", ["groundtruth_rect.1.txt",
                                                                                  "groundtruth_rect.2.txt"])):
        for f in gt_files:
            write(root / name / f, lines([[11, 21, 12, 10]] * 2))
        frames(root / name / "img", ["0001.jpg", "0002.jpg"], jpg)
    return root


def test_otb_attributes_from_the_toolkit_att_files_and_pysot_json(tmp_path, jpg):
    root = otb_root(tmp_path, jpg)
    assert all(s.attributes == {} for s in load_dataset("otb", root))  # none shipped, none found
    # the toolkit's column order: IV OPR SV OCC DEF MB FM IPR OV BC LR
    write(root / "anno" / "att" / "basketball.txt", "1 1 0 1 1 0 0 0 0 1 0\n")
    write(root / "OTB100.json", json.dumps({"Basketball": {"attr": ["LR"]},
                                            "Jogging-1": {"attr": ["OCC", "DEF", "OPR"]},
                                            "Jogging-2": {"video_dir": "Jogging", "attr": []}}))
    seqs = {s.name: s for s in load_dataset("otb", root)}
    assert list(seqs["Basketball"].attributes) == list(OTB_ATTRIBUTES)
    assert {a for a, v in seqs["Basketball"].attributes.items() if v} == {"IV", "OPR", "OCC", "DEF", "BC"}  # att wins
    assert {a for a, v in seqs["Jogging-1"].attributes.items() if v} == {"OCC", "DEF", "OPR"}
    assert not any(seqs["Jogging-2"].attributes.values()) and len(seqs["Jogging-2"].attributes) == 11
    assert detect_dataset(root) == "otb"  # anno/ and the JSON change nothing
    write(root / "OTB100.json", json.dumps({"Jogging-1": {"attr": ["OCC", "Blur"]}}))
    with pytest.raises(DatasetError, match=r"OTB100\.json: sequence 'Jogging-1': 'attr' must be a list of IV, OPR"):
        load_dataset("otb", root)
    write(root / "OTB100.json", "{\n  'Jogging-1': []\n}")
    with pytest.raises(DatasetError, match=r"OTB100\.json, line 2: not JSON"):
        load_dataset("otb", root)


# --------------------------------------------------------------------------- detection across layouts


def test_each_layout_is_detected_as_itself_and_the_older_ones_still_are(tmp_path, jpg):
    from test_datasets import dtb_root, touch_frames, uav_root, write_anno  # the older layouts' builders

    def place(name: str) -> Path:  # each in a folder of its own, named neutrally
        return tmp_path / name / "data"
    roots = {"lasot": lasot_root(place("lasot"), jpg, name="data"),
             "got10k_val": got_root(place("got"), jpg, ("val",)),
             "trackingnet": trackingnet_root(place("tn"), jpg) / "TEST",
             "trackingnet_train": trackingnet_root(place("tn2"), jpg) / "TRAIN_0",
             "vot": vot_root(place("vot"), jpg),
             "otb": otb_root(place("otb"), jpg),
             "uav123_10fps": uav_root(place("uav"), seqs=("wakeboard7",)),
             "dtb70": dtb_root(place("dtb"))[0]}
    uavdt = place("uavdt")
    write_anno(uavdt / "anno" / "S0601_gt.txt", 2)
    touch_frames(uavdt / "data_seq" / "S0601", "img%06d.jpg", 1, 2)
    roots["uavdt"] = uavdt
    assert {name: detect_dataset(root) for name, root in roots.items()} == {name: name for name in roots}
    assert [s.name for s in load_dataset("auto", roots["vot"])] == ["ants1", "bag"]
    with pytest.raises(DatasetError, match=r"sequence 'antz' not found in VOT at .* Did you mean 'ants1'\?"):
        load_dataset("vot", roots["vot"], "antz")


# --------------------------------------------------------------------------- end to end


def test_eval_and_report_on_lasot_give_per_attribute_tables(tmp_path, jpg, capsys):
    root = lasot_root(tmp_path, jpg)
    iv, arc = "1,0,0,0,0,0,0,0,0,0,0,0,0,0\n", "0,0,0,0,0,0,0,0,0,0,0,0,0,1\n"
    for name, flags in {"airplane-1": iv, "airplane-2": iv, "airplane-10": arc, "bird-3": iv}.items():
        write(root / "annos" / "att" / f"{name}.txt", flags)
    out = tmp_path / "out"
    kcf = str(Path(__file__).resolve().parents[2] / "configs" / "kcf.yaml")
    assert cli.main(["eval", kcf, "--dataset", "lasot", "--root", str(root), "--out", str(out), "--no-progress",
                     "--protocol", "lasot"]) == 0
    assert "kcf: 4 run, 0 already done, 0 failed" in capsys.readouterr().out
    assert cli.main(["report", str(out), "--dataset", "lasot", "--root", str(root), "--protocol", "lasot"]) == 0
    table = (out.parent / "out_report" / "per_attribute.txt").read_text()
    assert "Illumination Variation" in table and "Aspect Ratio Change" in table
    assert table.splitlines()[1].startswith("protocol lasot: LaSOT toolkit")
    rows = [r for r in json.loads((out.parent / "out_report" / "report.json").read_text())["per_attribute"]]
    assert {(r["attribute"], r["sequences"]) for r in rows} == {("IV", 3), ("ARC", 1)}
    assert (out.parent / "out_report" / "success_IV.png").is_file()


def test_a_benchmark_is_scored_by_its_own_toolkit_unless_protocol_says_otherwise(tmp_path, jpg, capsys):
    root, out = lasot_root(tmp_path, jpg), tmp_path / "out"
    kcf = str(Path(__file__).resolve().parents[2] / "configs" / "kcf.yaml")
    assert cli.main(["eval", kcf, "--dataset", "lasot", "--root", str(root), "--out", str(out), "--no-progress"]) == 0
    assert "(protocol lasot)" in capsys.readouterr().out
    assert cli.main(["report", str(out), "--dataset", "lasot", "--root", str(root)]) == 0
    assert cli.main(["report", str(out), "--dataset", "lasot", "--root", str(root), "--protocol", "otb",
                     "--report-dir", str(tmp_path / "otb")]) == 0
    default, otb = (json.loads((d / "report.json").read_text()) for d in (out.parent / "out_report", tmp_path / "otb"))
    assert default["protocol"]["name"] == "lasot" and otb["protocol"]["name"] == "otb"
    # the absent frames fail under LaSOT's rules and are skipped under the OTB toolkit's
    assert default["overall"][0]["precision"] < otb["overall"][0]["precision"]
    sequences = load_dataset("lasot", root)
    assert benchmark_protocol(sequences) == "lasot"
    assert benchmark_protocol([dataclasses.replace(s, dataset="") for s in sequences]) == "otb"
    with pytest.raises(RegistryError, match="unknown protocol 'nope'; protocols: otb, pysot"):
        reg.Registry(make_layout=new_layout).register_dataset("mine", lambda root, sequences=None: [], "ROOT", protocol="nope")


def test_eval_on_a_test_split_runs_and_report_says_there_is_nothing_to_score(tmp_path, jpg, capsys):
    root = got_root(tmp_path, jpg, ("test",))
    out = tmp_path / "out"
    kcf = str(Path(__file__).resolve().parents[2] / "configs" / "kcf.yaml")
    assert cli.main(["eval", kcf, "--dataset", "got10k_test", "--root", str(root), "--out", str(out),
                     "--no-progress"]) == 0
    printed = capsys.readouterr().out
    assert "kcf: 1 run" in printed and "no scores: the ground truth of these 1 sequences is withheld" in printed
    assert len((out / "kcf" / "GOT-10k_Test_000001.txt").read_text().splitlines()) == 4
    assert cli.main(["report", str(out), "--dataset", "got10k_test", "--root", str(root)]) == 2
    err = capsys.readouterr().err
    assert "no scores: got10k_test publishes the ground truth of frame 1 only" in err and "evaluation server" in err
    assert not (out.parent / "out_report").exists()


# --------------------------------------------------------------------------- dataset plugins


class FakeEntryPoint:
    def __init__(self, name, module):
        self.name, self.value, self._module = name, module, module

    def load(self):
        return sys.modules[self._module]


DATASET_PLUGIN = '''
import numpy as np
from pathlib import Path
from dcfkit.datasets import Sequence
from dcfkit.datasets.base import read_boxes, require_root
from dcfkit.registry import hookimpl

def load(root, sequences=None):
    root = require_root(root, "toyset")
    out = []
    for anno in sorted(root.glob("*/boxes.csv")):
        boxes = read_boxes(anno)
        frames = [anno.parent / f"{k}.jpg" for k in range(len(boxes))]
        out.append(Sequence(anno.parent.name, frames, boxes, {}, "toyset", anno))
    return out

def detect(root):
    return 2 if any(Path(root).glob("*/boxes.csv")) else 0

@hookimpl
def dcfkit_register_components(registry):
    registry.register_dataset(NAME, load, "ROOT/<seq>/boxes.csv, ROOT/<seq>/<k>.jpg", detect=detect,
                              aliases=ALIASES)
'''


def install(monkeypatch, plugins: dict[str, str]) -> None:
    """Make each ``module -> source`` importable and a ``dcfkit`` entry point; a fresh registry."""
    eps = []
    for module_name, source in plugins.items():
        module = types.ModuleType(module_name)
        exec(compile(source, f"<{module_name}>", "exec"), module.__dict__)
        monkeypatch.setitem(sys.modules, module_name, module)
        eps.append(FakeEntryPoint(module_name, module_name))
    own = reg.plugin_entry_points(external=False)[0]
    monkeypatch.setattr(reg.importlib.metadata, "entry_points", lambda group=None: own + eps if group == "dcfkit" else [])
    monkeypatch.delenv(reg.DISABLE_ENV, raising=False)
    monkeypatch.setattr(reg, "_REGISTRY", None)


def plugin(name: str = "toyset", aliases=("toy-set",), body: str = "") -> str:
    return f"NAME = {name!r}\nALIASES = {tuple(aliases)!r}\n" + DATASET_PLUGIN + body


def toyset_root(tmp_path: Path, jpg: Path) -> Path:
    root = tmp_path / "toys"
    write(root / "ant" / "boxes.csv", lines([[11, 21, 12, 10], [12, 21, 12, 10]]))
    frames(root / "ant", ["0.jpg", "1.jpg"], jpg)
    return root


def test_a_plugin_registers_a_dataset_that_loads_detects_and_is_listed(tmp_path, jpg, monkeypatch, capsys):
    install(monkeypatch, {"dcfkit_test_toyset": plugin()})
    root = toyset_root(tmp_path, jpg)
    (ant,) = load_dataset("Toy-Set", root)
    assert (ant.name, ant.dataset, len(ant)) == ("ant", "toyset", 2)
    np.testing.assert_array_equal(ant.ground_truth[0], [10, 20, 12, 10])
    assert detect_dataset(root) == "toyset"
    assert cli.main(["datasets"]) == 0
    listed = [line for line in capsys.readouterr().out.splitlines() if line.startswith("toyset ")]
    assert listed == ["toyset             ROOT/<seq>/boxes.csv, ROOT/<seq>/<k>.jpg  "
                      "[dcfkit_test_toyset (dcfkit_test_toyset)]"]
    assert cli.main(["datasets", "--format", "json"]) == 0
    rows = {r["name"]: r for r in json.loads(capsys.readouterr().out)}
    assert rows["toyset"]["aliases"] == ["toy_set"] and rows["lasot"]["provider"] == "dcfkit"
    assert {"lasot", "got10k_val", "trackingnet", "vot", "otb"} <= set(rows)
    monkeypatch.setenv(reg.DISABLE_ENV, "1")
    monkeypatch.setattr(reg, "_REGISTRY", None)
    with pytest.raises(DatasetError, match="unknown dataset 'toyset'"):
        load_dataset("toyset", root)
    monkeypatch.setattr(reg, "_REGISTRY", None)


def test_a_plugin_dataset_with_a_taken_name_is_skipped_and_named(tmp_path, jpg, monkeypatch, capsys):
    install(monkeypatch, {"dcfkit_test_thief": plugin("toyset", aliases=("lasot",)),
                          "dcfkit_test_good": plugin("toyset2", aliases=())})
    with pytest.warns(reg.PluginWarning, match=r"dcfkit plugin 'dcfkit_test_thief .*' failed and was skipped: "
                                               r"dataset layout 'toyset' \(from dcfkit_test_thief.*\): the name "
                                               r"'lasot' is already registered; give the plugin's layout another name"):
        seqs = load_dataset("toyset2", toyset_root(tmp_path, jpg))
    assert [s.name for s in seqs] == ["ant"]
    with pytest.raises(DatasetError, match=r"(?s)unknown dataset 'toyset'.*\nSkipped plugins: dcfkit plugin "
                                           r"'dcfkit_test_thief"):
        load_dataset("toyset", tmp_path)
    assert cli.main(["datasets"]) == 1
    assert capsys.readouterr().err.count("warning: dcfkit plugin 'dcfkit_test_thief") == 1
    monkeypatch.setattr(reg, "_REGISTRY", None)


def test_a_dataset_name_two_plugins_register_is_withdrawn(tmp_path, jpg, monkeypatch):
    install(monkeypatch, {"dcfkit_test_a": plugin("toyset", aliases=("toy_a",)),
                          "dcfkit_test_b": plugin("toyset", aliases=("toy_b",))})
    root = toyset_root(tmp_path, jpg)
    with pytest.warns(reg.PluginWarning, match=r"dcfkit_test_a .* and dcfkit_test_b .* all register dataset 'toyset'"):
        with pytest.raises(RegistryError, match=r"dataset 'toyset' is registered by more than one plugin"):
            load_dataset("toyset", root)
    assert load_dataset("toy_b", root)[0].dataset == "toyset"  # their other names stay
    with pytest.raises(DatasetError, match="no known benchmark layout"):  # neither is listed, nor detects
        detect_dataset(root)
    monkeypatch.setattr(reg, "_REGISTRY", None)


def test_a_plugin_whose_detect_raises_is_left_out_of_detection(tmp_path, jpg, monkeypatch):
    broken = plugin("toyset") + "\ndef detect(root):\n    raise KeyError('oops')\n"
    install(monkeypatch, {"dcfkit_test_detect": broken})
    root = lasot_root(tmp_path, jpg)
    with pytest.warns(reg.PluginWarning, match=r"dataset layout 'toyset' of dcfkit plugin 'dcfkit_test_detect .*' was "
                                               r"left out of detection: .* raised KeyError: 'oops'"):
        assert detect_dataset(root) == "lasot"
    monkeypatch.setattr(reg, "_REGISTRY", None)


def test_the_registry_checks_a_dataset_registration():
    r = reg.Registry(make_layout=new_layout)
    layout = r.register_dataset("Mine", lambda root, sequences=None: [], "ROOT/<seq>/x.txt", aliases=("my-set",))
    assert r.dataset("my_set") is layout and r.datasets() == [layout] and r.dataset("other") is None
    with pytest.raises(RegistryError, match="load and detect must be functions"):
        r.register_dataset("mine2", "not a function", "ROOT")
    with pytest.raises(RegistryError, match="the description must be one non-empty line"):
        r.register_dataset("mine3", lambda root, sequences=None: [], "two\nlines")
    with pytest.raises(RegistryError, match="dataset 'mine' from \\? is already registered by \\?"):
        r.register_dataset("mine", lambda root, sequences=None: [], "ROOT")


def test_sequences_made_by_hand_are_scored_unless_withheld():
    seq = Sequence("s", ["a.jpg", "b.jpg"], [[1, 1, 5, 5], NAN], ground_truth_withheld=True)
    assert "ground truth withheld" in repr(seq)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        from dcfkit.datasets import scored_sequences
        plain = Sequence("t", ["a.jpg"], [[1, 1, 5, 5]])
        assert scored_sequences([seq, plain]) == [plain]
        with pytest.raises(DatasetError, match="no scores: this dataset publishes the ground truth of frame 1 only"):
            scored_sequences([seq])


def test_the_dataset_plugin_of_the_tutorial_runs(tmp_path, jpg, monkeypatch, capsys):
    tutorial = (Path(__file__).resolve().parents[2] / "docs" / "plugins.md").read_text(encoding="utf-8")
    (source,) = re.findall(r"<!-- example: dataset plugin -->\n```python\n(.*?)```", tutorial, re.S)
    install(monkeypatch, {"dcfkit_tc128": source})
    root = tmp_path / "Temple-color-128"
    write(root / "Airport_ce" / "Airport_ce_gt.txt", lines([[11, 21, 12, 10], [12, 21, 12, 10], [13, 21, 12, 10]]))
    write(root / "Airport_ce" / "Airport_ce_frames.txt", "2,4\n")
    frames(root / "Airport_ce" / "img", ["0001.jpg", "0002.jpg", "0003.jpg", "0004.jpg"], jpg)
    assert detect_dataset(root) == "tc128"
    (seq,) = load_dataset("temple-color-128", root)
    assert [f.name for f in seq.frames] == ["0002.jpg", "0003.jpg", "0004.jpg"] and seq.dataset == "tc128"
    np.testing.assert_array_equal(seq.ground_truth[0], [10, 20, 12, 10])
    assert cli.main(["datasets"]) == 0
    assert "[dcfkit_tc128 (dcfkit_tc128)]" in capsys.readouterr().out
    write(root / "Airport_ce" / "Airport_ce_frames.txt", "2,5\n")
    with pytest.raises(DatasetError, match=r"Airport_ce_gt\.txt: 3 annotation lines but 4 frames \(frames 2\.\.5\)"):
        load_dataset("tc128", root)
    monkeypatch.setattr(reg, "_REGISTRY", None)


# --------------------------------------------------------------------------- hostile annotation files


def replace_file(path: Path, kind: str, text: str = "") -> None:
    """``path`` as a FIFO, a link to /dev/zero, or holding ``text``."""
    path.unlink()
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "zero":
        os.symlink("/dev/zero", path)
    else:
        path.write_text(text)


@pytest.mark.parametrize("layout, file, kind, text, said", [
    ("lasot", "airplane/airplane-2/full_occlusion.txt", "text", "0,0,1e30,0", r"got '1e30' for frame 3"),
    ("lasot", "airplane/airplane-2/full_occlusion.txt", "text", "0,0,0", r"more values than its 2 frames"),
    ("lasot", "airplane/airplane-2/out_of_view.txt", "fifo", "", r"out_of_view\.txt \(not a regular file\)"),
    ("lasot", "airplane/airplane-2/full_occlusion.txt", "zero", "", r"full_occlusion\.txt \(not a regular file\)"),
    ("lasot", "airplane/airplane-2/groundtruth.txt", "text", "1," * 3_000_000, r"line 1: 6000000 characters, too long"),
    ("lasot", "airplane/airplane-2/groundtruth.txt", "text", "1,2,3,٣\n1,2,3,4\n", r"line 1: expected 4 numbers"),
    ("lasot", "airplane/airplane-2/groundtruth.txt", "text", "1,2,3,2_0\n1,2,3,4\n", r"line 1: expected 4 numbers"),
    ("got10k_val", "val/GOT-10k_Val_000001/cover.label", "text", "8\n1e19\n5\n", r"got '1e19' for frame 2"),
    ("vot", "ants1/groundtruth.txt", "text", "m0,0,10,10,99999999999999999999999,3\n",
     r"line 1: expected a region .*at most 10 digits"),
    ("vot", "ants1/sequence", "text", "channels.color=color/%0999999999d.jpg\n", r"is not a frame pattern"),
    ("vot", "ants1/sequence", "text", "channels.color=color/%099999999999999999999d.jpg\n", r"is not a frame pattern"),
    ("otb", "Basketball/groundtruth_rect.txt", "text", "", r"sequence 'Basketball' has no frames"),
])
def test_hostile_annotation_files_are_one_line_errors(layout, file, kind, text, said, tmp_path, jpg):
    """Each broke the loader with OverflowError, MemoryError, IndexError, or a hang."""
    root = {"lasot": lasot_root, "got10k_val": got_root, "vot": vot_root, "otb": otb_root}[layout](tmp_path, jpg)
    replace_file(root / file, kind, text)
    if layout == "otb":  # an empty img/ too
        for image in (root / "Basketball" / "img").iterdir():
            image.unlink()
    with pytest.raises(DatasetError, match=said):
        load_dataset(layout, root)


ANNOTATION_PIECES = [b"0", b"1", b"7", b"12.5", b"-3", b"1e30", b"1e19", b"9" * 30, b"nan", b"inf", b"NaN", b",", b" ",
                     b"\t", b"\n", b"\r\n", b".", b"e", b"-", b"_", "٣".encode(), b"m", b"m0,0,2,2,1,2", b"\xff",
                     b"\xef\xbb\xbf", b"\x00"]


@settings(max_examples=150, deadline=None)
@given(data=st.lists(st.sampled_from(ANNOTATION_PIECES), max_size=60), n_frames=st.integers(1, 6))
def test_fuzzed_annotation_files_read_or_say_why(tmp_path_factory, data, n_frames):
    """Whatever bytes an annotation file holds, each reader returns what it promises (shape,
    dtype) or raises a DatasetError naming the file; never another exception."""
    from dcfkit.datasets.annotations import read_boxes, read_flags, read_frame_values
    from dcfkit.datasets.vot_layout import read_regions

    path = tmp_path_factory.mktemp("fuzz") / "annotation.txt"
    path.write_bytes(b"".join(data))
    boxes = lambda out: out.dtype == np.float64 and out.shape[1:] == (4,)  # noqa: E731
    readers = [(lambda: read_boxes(path), boxes), (lambda: read_regions(path), boxes),
               (lambda: read_frame_values(path, n_frames), lambda out: out.shape == (n_frames,) and out.dtype == np.int64),
               (lambda: read_flags(path, ("SV", "OCC")), lambda out: set(out) == {"SV", "OCC"})]
    for read, promised in readers:
        try:
            out = read()
        except DatasetError as exc:
            assert str(path) in str(exc) and "\n" not in str(exc)
            continue
        assert promised(out), out


def test_two_otb_targets_of_one_name_are_an_error_naming_both_files(tmp_path, jpg):
    root = otb_root(tmp_path, jpg)  # Jogging holds targets 1 and 2: Jogging-1, Jogging-2
    write(root / "Jogging-1" / "groundtruth_rect.txt", lines([[11, 21, 12, 10]] * 2))
    frames(root / "Jogging-1" / "img", ["0001.jpg", "0002.jpg"], jpg)
    with pytest.raises(DatasetError, match=r"two targets are named 'Jogging-1': .*Jogging/groundtruth_rect\.1\.txt "
                                           r"and .*Jogging-1/groundtruth_rect\.txt"):
        load_dataset("otb", root)


def test_only_numbered_files_are_targets_of_a_multi_target_folder(tmp_path, jpg):
    root = otb_root(tmp_path, jpg)
    write(root / "Jogging" / "groundtruth_rect.1.old.txt", lines([[1, 1, 5, 5]] * 2))  # a backup, not a target
    sequences = {s.name: s for s in load_dataset("otb", root)}
    assert sorted(sequences) == ["Basketball", "Jogging-1", "Jogging-2"]
    assert sequences["Jogging-1"].annotation.name == "groundtruth_rect.1.txt"


@pytest.mark.parametrize("kind", ["fifo", "zero", "folder"])
def test_a_sequence_whose_annotation_cannot_be_read_is_named_not_dropped(kind, tmp_path, jpg):
    root = otb_root(tmp_path, jpg)
    annotation = root / "Basketball" / "groundtruth_rect.txt"
    if kind == "folder":
        annotation.unlink()
        annotation.mkdir()
    else:
        replace_file(annotation, kind)
    with pytest.raises(DatasetError, match=r"Basketball/groundtruth_rect\.txt \(not a regular file\)"):
        load_dataset("otb", root)


@pytest.mark.parametrize("text, said", [
    ("1,2,3,4\n1e309,2,3,4\n", r"line 2: .*got '1e309,2,3,4'"),
    ("1,2,3,4\x0c\n1,2,3,x\n", r"line 2: .*got '1,2,3,x'"),  # a form feed is no line break
    ("1,2,3,4\u2028\n1,2,3,x\n", r"line 2: .*got '1,2,3,x'"),
])
def test_numbers_out_of_range_and_line_numbers_of_odd_files(text, said, tmp_path):
    from dcfkit.datasets import read_boxes

    path = write(tmp_path / "groundtruth.txt", text)
    with pytest.raises(DatasetError, match=said):
        read_boxes(path)


def test_a_vot_frame_pattern_takes_ascii_digits_only(tmp_path, jpg):
    root = vot_root(tmp_path, jpg)
    write(root / "ants1" / "sequence", "channels.color=color/%0\u0668d.jpg\n")  # an Arabic-Indic eight
    with pytest.raises(DatasetError, match=r"is not a frame pattern"):
        load_dataset("vot", root)
