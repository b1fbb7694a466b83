"""dcfkit export vot: any dataset as a VOT workspace's sequences, read back by dcfkit's VOT
layout (which follows the VOT toolkit's reading: 0-based rectangles, channels.color)."""
from __future__ import annotations

import os
from pathlib import Path

import cv2
import numpy as np
import pytest

from dcfkit import cli
from dcfkit.datasets import DatasetError, Sequence, load_dataset
from dcfkit.datasets.synthetic import make_sequence
from dcfkit.errors import DcfkitError
from dcfkit.integrations.vot import export_sequences


def otb_like(tmp_path: Path, name: str, n: int = 5, dataset: str = "synthetic") -> Sequence:
    syn = make_sequence(n_frames=n, size=(40, 60), target=(8, 10))
    folder = tmp_path / "src" / dataset / name
    folder.mkdir(parents=True)
    frames = []
    for i, image in enumerate(syn.frames):
        frames.append(folder / f"{i:04d}.png")
        cv2.imwrite(str(frames[-1]), image)
    boxes = syn.ground_truth.copy()
    boxes[2] = np.nan  # an absent target
    return Sequence(name, tuple(frames), boxes, {}, dataset)


@pytest.mark.parametrize("copy", [False, True])
def test_an_exported_workspace_loads_as_vot_with_the_same_frames_and_boxes(tmp_path, copy):
    seqs = [otb_like(tmp_path, "a"), otb_like(tmp_path, "b", 3)]
    assert export_sequences(seqs, tmp_path / "ws", copy=copy) == {"written": ["a", "b"], "skipped": [],
                                                                   "listed": ["a", "b"]}
    root = tmp_path / "ws" / "sequences"
    assert (root / "list.txt").read_text() == "a\nb\n"
    assert (root / "a" / "sequence").read_text().splitlines()[0] == "channels.color=color/%08d.png"
    assert (root / "a" / "groundtruth.txt").read_text().splitlines()[2] == "nan,nan,nan,nan"
    assert (root / "a" / "color" / "00000001.png").is_symlink() != copy
    loaded = load_dataset("vot", root)
    assert [s.name for s in loaded] == ["a", "b"]
    for ours, theirs in zip(seqs, loaded):
        np.testing.assert_allclose(theirs.ground_truth, ours.ground_truth, atol=1e-4)  # 0-based both
        assert len(theirs) == len(ours) and np.array_equal(theirs.frame(1), ours.frame(1))


def test_refusals(tmp_path):
    seq = otb_like(tmp_path, "a")
    export_sequences([seq], tmp_path / "ws")
    other = otb_like(tmp_path, "a", n=4, dataset="other")  # another sequence of the same name
    with pytest.raises(DatasetError, match=r"ws/sequences/a exists and is not this export "
                                           r"\(groundtruth.txt, color/ \(5 frames, not 4\) differ\): "
                                           r"nothing is overwritten"):
        export_sequences([other], tmp_path / "ws")
    with pytest.raises(DatasetError, match="sequence name 'a' is given twice; nothing was written"):
        export_sequences([otb_like(tmp_path, "b"), seq, seq], tmp_path / "ws")
    mixed = Sequence("m", (Path("x.png"), Path("y.jpg")), np.zeros((2, 4)), {}, "t")
    with pytest.raises(DatasetError, match="several file types"):
        export_sequences([mixed], tmp_path / "ws2")
    assert sorted(p.name for p in (tmp_path / "ws" / "sequences").iterdir()) == ["a", "list.txt"]


def test_an_export_adds_to_the_workspace_and_keeps_its_list(tmp_path):
    """list.txt was rewritten with the new sequences only; the old ones were still on disk."""
    a, b = otb_like(tmp_path, "a"), otb_like(tmp_path, "b", 3)
    export_sequences([a], tmp_path / "ws")
    export_sequences([b], tmp_path / "ws")
    assert (tmp_path / "ws" / "sequences" / "list.txt").read_text() == "a\nb\n"
    assert export_sequences([b, a], tmp_path / "ws") == {"written": [], "skipped": ["b", "a"], "listed": ["a", "b"]}
    assert [s.name for s in load_dataset("vot", tmp_path / "ws" / "sequences")] == ["a", "b"]


def test_an_export_stopped_half_way_is_resumed(tmp_path, monkeypatch):
    """A sequence folder half written made every rerun fail with "exists"."""
    a, b = otb_like(tmp_path, "a"), otb_like(tmp_path, "b")
    links = []

    def stop_at_the_seventh_link(source, destination):
        links.append(destination)
        if len(links) == 7:  # b's second frame
            raise KeyboardInterrupt
        real_symlink(source, destination)

    real_symlink = os.symlink
    monkeypatch.setattr(os, "symlink", stop_at_the_seventh_link)
    with pytest.raises(KeyboardInterrupt):
        export_sequences([a, b], tmp_path / "ws")
    monkeypatch.undo()
    root = tmp_path / "ws" / "sequences"
    assert not (root / "b").exists()  # b is not there half-written
    assert export_sequences([a, b], tmp_path / "ws") == {"written": ["b"], "skipped": ["a"], "listed": ["a", "b"]}
    assert sorted(p.name for p in root.iterdir()) == ["a", "b", "list.txt"]  # the partial folder replaced
    assert [len(s) for s in load_dataset("vot", root)] == [5, 5]
    (tmp_path / "keep").mkdir()
    (tmp_path / "keep" / "file").write_text("x")
    (root / ".c.partial").symlink_to(tmp_path / "keep")  # a partial folder that is a link: removed, not followed
    export_sequences([otb_like(tmp_path, "c")], tmp_path / "ws")
    assert (tmp_path / "keep" / "file").read_text() == "x" and not os.path.lexists(root / ".c.partial")


def test_a_frame_that_cannot_be_copied_is_one_line_and_leaves_no_sequence(tmp_path):
    seq = otb_like(tmp_path, "a")
    seq.frames[3].unlink()
    with pytest.raises(DcfkitError, match=r"sequence 'a': cannot export it into .*ws/sequences: "
                                          r"No such file .*0003.png"):
        export_sequences([seq], tmp_path / "ws", copy=True)
    assert not (tmp_path / "ws" / "sequences" / "a").exists()


@pytest.mark.parametrize("name", ["a\nb", "a\rb", " a", "../a", ""])
def test_a_name_that_is_not_one_list_line_and_one_folder_is_refused(tmp_path, name):
    """A newline in a sequence's name split list.txt into two entries, neither a sequence."""
    seq = otb_like(tmp_path, "x")
    with pytest.raises(DatasetError, match=r"export vot: sequence name .* nothing was written"):
        export_sequences([otb_like(tmp_path, "ok"), Sequence(name, seq.frames, seq.ground_truth)], tmp_path / "ws")
    assert not (tmp_path / "ws").exists()


@pytest.mark.parametrize("dataset, fps", [("uav123_10fps", 10), ("got10k_val", 10), ("uav123", 30), ("otb", 30)])
def test_the_sequence_file_gives_the_dataset_s_frame_rate(tmp_path, dataset, fps):
    """UAV123@10fps was written fps=30."""
    export_sequences([otb_like(tmp_path, "s", 3, dataset)], tmp_path / "ws")
    assert f"fps={fps}\n" in (tmp_path / "ws" / "sequences" / "s" / "sequence").read_text()


def test_the_command_exports_a_benchmark(tmp_path, capsys):
    root = tmp_path / "OTB"
    seq = otb_like(tmp_path, "x")
    (root / "Car" / "img").mkdir(parents=True)
    for i, frame in enumerate(seq.frames):
        cv2.imwrite(str(root / "Car" / "img" / f"{i + 1:04d}.jpg"), cv2.imread(str(frame)))
    gt = np.nan_to_num(seq.ground_truth, nan=1.0) + [1, 1, 0, 0]
    (root / "Car" / "groundtruth_rect.txt").write_text("".join(",".join(f"{v:g}" for v in b) + "\n" for b in gt))
    assert cli.main(["export", "vot", "--dataset", "otb", "--root", str(root), "--out", str(tmp_path / "ws")]) == 0
    out = capsys.readouterr().out
    assert "1 sequences written" in out and "note: fps=30 written for 'otb', the VOT toolkit's default" in out
    (car,) = load_dataset("vot", tmp_path / "ws" / "sequences")
    np.testing.assert_allclose(car.ground_truth, gt - [1, 1, 0, 0], atol=1e-4)


def got10k_test_root(tmp_path: Path) -> Path:
    """A GOT-10k test split: one 6-frame sequence whose groundtruth.txt has frame 1's box only."""
    folder = tmp_path / "GOT-10k" / "test" / "GOT-10k_Test_000001"
    folder.mkdir(parents=True)
    for k in range(1, 7):
        cv2.imwrite(str(folder / f"{k:08d}.jpg"), np.full((24, 32, 3), 9 * k, np.uint8))
    (folder / "groundtruth.txt").write_text("11,21,12,10\n")
    (folder.parent / "list.txt").write_text("GOT-10k_Test_000001\n")
    return tmp_path / "GOT-10k"


def test_a_test_split_whose_ground_truth_is_withheld_is_refused(tmp_path, capsys):
    """Its NaN rows would be read by VOT as 'target absent' on every frame after the first."""
    args = ["export", "vot", "--dataset", "got10k_test", "--root", str(got10k_test_root(tmp_path)), "--out",
            str(tmp_path / "ws")]
    assert cli.main(args) != 0
    err = capsys.readouterr().err.strip()
    assert "sequence 'GOT-10k_Test_000001': its ground truth after frame 1 is withheld (a test split)" in err
    assert "\n" not in err and not (tmp_path / "ws").exists()


def test_a_dangling_link_where_a_sequence_goes_is_named(tmp_path):
    (tmp_path / "ws" / "sequences").mkdir(parents=True)
    os.symlink(tmp_path / "gone", tmp_path / "ws" / "sequences" / "b")
    with pytest.raises(DcfkitError, match=r"ws/sequences/b is a symbolic link \(to .*gone, which does not exist\)"):
        export_sequences([otb_like(tmp_path, "b")], tmp_path / "ws")
    assert os.path.islink(tmp_path / "ws" / "sequences" / "b")


def test_a_rerun_never_skips_a_sequence_whose_frame_links_lead_nowhere(tmp_path):
    """An export linked to frames that moved since was "already there" on a rerun from the new
    place: the workspace held links the toolkit could not read."""
    a = otb_like(tmp_path, "a")
    export_sequences([a], tmp_path / "ws")
    moved = tmp_path / "moved"
    (tmp_path / "src").rename(moved)
    a2 = Sequence("a", tuple(moved / Path(f).relative_to(tmp_path / "src") for f in a.frames), a.ground_truth, {},
                  a.dataset)
    with pytest.raises(DatasetError, match=r"ws/sequences/a exists and is not this export \(color/ \(5 of its "
                                           r"frames lead nowhere\) differ\): nothing is overwritten"):
        export_sequences([a2], tmp_path / "ws")
