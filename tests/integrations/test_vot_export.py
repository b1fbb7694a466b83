"""dcfkit export vot: any dataset as a VOT workspace's sequences, read back by dcfkit's VOT
layout (which follows the VOT toolkit's reading: 0-based rectangles, channels.color)."""
from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest

from dcfkit import cli
from dcfkit.datasets import DatasetError, Sequence, load_dataset
from dcfkit.datasets.synthetic import make_sequence
from dcfkit.integrations.vot import export_sequences


def otb_like(tmp_path: Path, name: str, n: int = 5) -> Sequence:
    syn = make_sequence(n_frames=n, size=(40, 60), target=(8, 10))
    folder = tmp_path / "src" / name
    folder.mkdir(parents=True)
    frames = []
    for i, image in enumerate(syn.frames):
        frames.append(folder / f"{i:04d}.png")
        cv2.imwrite(str(frames[-1]), image)
    boxes = syn.ground_truth.copy()
    boxes[2] = np.nan  # an absent target
    return Sequence(name, tuple(frames), boxes, {}, "synthetic")


@pytest.mark.parametrize("copy", [False, True])
def test_an_exported_workspace_loads_as_vot_with_the_same_frames_and_boxes(tmp_path, copy):
    seqs = [otb_like(tmp_path, "a"), otb_like(tmp_path, "b", 3)]
    assert export_sequences(seqs, tmp_path / "ws", copy=copy) == ["a", "b"]
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


def test_refusals(tmp_path, capsys):
    seq = otb_like(tmp_path, "a")
    export_sequences([seq], tmp_path / "ws")
    with pytest.raises(DatasetError, match="exists: export into an empty workspace"):
        export_sequences([seq], tmp_path / "ws")
    mixed = Sequence("m", (Path("x.png"), Path("y.jpg")), np.zeros((2, 4)), {}, "t")
    with pytest.raises(DatasetError, match="several file types"):
        export_sequences([mixed], tmp_path / "ws2")


def test_the_command_exports_a_benchmark(tmp_path, capsys):
    root = tmp_path / "OTB"
    seq = otb_like(tmp_path, "x")
    (root / "Car" / "img").mkdir(parents=True)
    for i, frame in enumerate(seq.frames):
        cv2.imwrite(str(root / "Car" / "img" / f"{i + 1:04d}.jpg"), cv2.imread(str(frame)))
    gt = np.nan_to_num(seq.ground_truth, nan=1.0) + [1, 1, 0, 0]
    (root / "Car" / "groundtruth_rect.txt").write_text("".join(",".join(f"{v:g}" for v in b) + "\n" for b in gt))
    assert cli.main(["export", "vot", "--dataset", "otb", "--root", str(root), "--out", str(tmp_path / "ws")]) == 0
    assert "1 sequences written" in capsys.readouterr().out
    (car,) = load_dataset("vot", tmp_path / "ws" / "sequences")
    np.testing.assert_allclose(car.ground_truth, gt - [1, 1, 0, 0], atol=1e-4)
