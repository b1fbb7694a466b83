"""dcfkit.integrations.got10k with the real got10k toolkit (the ``got10k`` extra, in ``test``):
its frame loop and DTB70 experiment hand the adapter PIL RGB images and 1-based boxes, and
get back the boxes dcfkit itself computes on BGR frames, 1-based as dcfkit's result files."""
from __future__ import annotations

import importlib
import json
import os
import sys
from pathlib import Path

import cv2
import numpy as np
import pytest
from PIL import Image

import dcfkit
import dcfkit.integrations
from dcfkit.analysis.scoring import evaluate
from dcfkit.config import load_config
from dcfkit.datasets import load_dataset, read_frame
from dcfkit.datasets.synthetic import make_sequence
from dcfkit.errors import ConfigError, InputError, TrackingError
from dcfkit.running.evaluation import run_one_pass
from dcfkit.store.results import load_results
from dcfkit.experiments.loop import track

ONE_BASED = np.array([1.0, 1.0, 0.0, 0.0])


@pytest.fixture(scope="module")
def adapter():
    pytest.importorskip("got10k", reason='the got10k toolkit is not installed (pip install "dcfkit[got10k]")')
    return importlib.import_module("dcfkit.integrations.got10k")


def synthetic_folder(folder: Path, seed: int, n_frames: int = 8):
    """A synthetic sequence as PNG files (lossless: the pixels read back are the ones made), its
    BGR frames and 0-based ground truth."""
    seq = make_sequence(n_frames=n_frames, size=(200, 260), target=(22, 36), distractor=False, seed=seed)
    folder.mkdir()
    files = [str(folder / f"{i + 1:05d}.png") for i in range(n_frames)]
    for path, frame in zip(files, seq.frames):
        assert cv2.imwrite(path, frame)
    return files, seq.frames, seq.ground_truth


def dcfkit_boxes(frames, box0: np.ndarray) -> np.ndarray:
    """dcfkit's own tracker on BGR frames from a 0-based box: 0-based boxes."""
    return track(dcfkit.load_tracker("strcf"), frames, box0).boxes


def test_got10ks_loop_gets_dcfkits_boxes_in_its_own_convention(adapter, tmp_path):
    """got10k's Tracker.track opens each file with PIL (RGB) and passes the 1-based first box;
    the boxes it gets back are dcfkit's on the BGR frames, plus 1 on x and y. Two sequences
    on one adapter object, as an experiment runs them: the second starts afresh."""
    tracker = adapter.Tracker("strcf")
    for seed in (0, 1):
        files, frames, truth = synthetic_folder(tmp_path / f"seq{seed}", seed)
        boxes, times = tracker.track(files, truth[0] + ONE_BASED)
        reference = dcfkit_boxes(frames, truth[0])
        np.testing.assert_allclose(boxes, reference + ONE_BASED, rtol=0, atol=1e-9)
        assert np.abs(boxes - (truth + ONE_BASED))[:, :2].max() < 3  # on the target, in 1-based pixels
        assert len(times) == len(files) and (times > 0).all()


@pytest.mark.parametrize("kind", ["gray PIL image", "image path", "RGB array"])
def test_other_frames_got10k_can_hand_over(adapter, tmp_path, kind):
    """ExperimentVOT hands Image.open's image unconverted (grayscale 'L' sequences included) or,
    with read_image=False, the path; an array is taken in got10k's order, RGB."""
    files, frames, truth = synthetic_folder(tmp_path / "seq", 2, n_frames=5)
    if kind == "gray PIL image":
        frames = [cv2.cvtColor(cv2.cvtColor(f, cv2.COLOR_BGR2GRAY), cv2.COLOR_GRAY2BGR) for f in frames]
        given = [Image.fromarray(f[:, :, 0]) for f in frames]
        assert given[0].mode == "L"
    elif kind == "image path":
        given = files
    else:
        given = [np.ascontiguousarray(f[:, :, ::-1]) for f in frames]
    tracker = adapter.Tracker("strcf")
    tracker.init(given[0], truth[0] + ONE_BASED)
    boxes = [truth[0] + ONE_BASED] + [tracker.update(image) for image in given[1:]]
    np.testing.assert_allclose(boxes, dcfkit_boxes(frames, truth[0]) + ONE_BASED, rtol=0, atol=1e-9)


def test_a_zero_based_dataset_passes_boxes_unchanged(adapter, tmp_path):
    files, frames, truth = synthetic_folder(tmp_path / "seq", 3, n_frames=4)
    boxes, _ = adapter.Tracker("strcf", one_based=False).track(files, truth[0])
    np.testing.assert_allclose(boxes, dcfkit_boxes(frames, truth[0]), rtol=0, atol=1e-9)


def test_is_a_got10k_tracker_named_by_the_config(adapter):
    from got10k.trackers import Tracker as Got10kTracker  # deferred: the adapter fixture skips without got10k

    tracker = adapter.Tracker("strcf", name="strcf_theta20", overrides={"regularizers.temporal.theta": 20})
    assert isinstance(tracker, Got10kTracker) and tracker.is_deterministic
    assert tracker.name == "strcf_theta20" and tracker.config["regularizers"]["temporal"]["theta"] == 20
    assert adapter.Tracker({"base": "strcf.yaml", "name": "mine"}).name == "mine"
    with pytest.raises(ConfigError, match="folder name"):
        adapter.Tracker("strcf", name="a/b")  # got10k would write results/<benchmark>/a/b/
    with pytest.raises(ConfigError, match="no_such_key"):
        adapter.Tracker("strcf", overrides={"tracker.no_such_key": 1})


def opened(path: str) -> Image.Image:
    """The image got10k's loop would hand over, its file closed."""
    with Image.open(path) as image:
        image.load()
    return image


def test_misuse_is_dcfkits_error_naming_the_frame(adapter, tmp_path):
    files, frames, truth = synthetic_folder(tmp_path / "seq", 4, n_frames=3)
    images = [opened(f) for f in files]
    tracker = adapter.Tracker("strcf")
    with pytest.raises(TrackingError, match="before init"):
        tracker.update(images[1])
    tracker.init(images[0], truth[0] + ONE_BASED)
    tracker.update(images[1])
    with pytest.raises(InputError, match="4 numbers"):
        tracker.init(images[0], "10,10,5")
    with pytest.raises(TrackingError, match="before init"):  # not the last sequence's tracker
        tracker.update(images[1])
    tracker.init(images[0], truth[0] + ONE_BASED)
    with pytest.raises(InputError, match="frame 2: expected a PIL image"):
        tracker.update(b"not an image")
    with pytest.raises(InputError, match="frame 3: the image is"):
        tracker.update(images[2].crop((0, 0, 100, 100)))


def test_without_got10k_the_import_names_the_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "got10k", None)  # what an absent package looks like to import
    monkeypatch.setitem(sys.modules, "got10k.trackers", None)
    monkeypatch.delitem(sys.modules, "dcfkit.integrations.got10k", raising=False)
    monkeypatch.delattr(dcfkit.integrations, "got10k", raising=False)
    with pytest.raises(ModuleNotFoundError, match=r'pip install "dcfkit\[got10k\]"'):
        importlib.import_module("dcfkit.integrations.got10k")


# --------------------------------------------------------------------------- real data


def dtb70_excerpt(source: Path, root: Path, parts: dict[str, tuple[int, int]]) -> Path:
    """A DTB70-layout folder of ``name -> (first, n)`` excerpts of ``source`` (frames linked,
    renumbered from 1; the matching annotation lines)."""
    lines = (source / "groundtruth_rect.txt").read_text().splitlines()
    for name, (first, n) in parts.items():
        (root / name / "img").mkdir(parents=True)
        for k in range(n):
            os.symlink(source / "img" / f"{first + k:05d}.jpg", root / name / "img" / f"{k + 1:05d}.jpg")
        (root / name / "groundtruth_rect.txt").write_text("\n".join(lines[first - 1:first - 1 + n]) + "\n")
    return root


def test_experiment_dtb70_writes_what_dcfkit_eval_writes(adapter, shared_data, tmp_path):
    """got10k's ExperimentDTB70 run and report on two excerpts of Gull1, against dcfkit's own
    one-pass evaluation of the same folder: the same result files, and the report's scores
    are those of dcfkit's ``pysot`` protocol, whose rules its OTB experiment shares
    (continuous IoU, ``> t`` on 21 thresholds, precision at 20 px, sequences equal)."""
    from got10k.experiments import ExperimentDTB70  # deferred: the adapter fixture skips without got10k

    gull = shared_data / "DTB70" / "Gull1"
    first = gull / "img" / "00001.jpg"
    assert (read_frame(first) == np.asarray(Image.open(first))[:, :, ::-1]).all(), \
        f"Pillow and OpenCV decode {first} differently here: got10k's boxes cannot be dcfkit eval's"
    root = dtb70_excerpt(gull, tmp_path / "DTB70", {"Gull1": (1, 12), "Gull1_61": (61, 12)})
    experiment = ExperimentDTB70(str(root), result_dir=str(tmp_path / "results"), report_dir=str(tmp_path / "reports"))
    experiment.run(adapter.Tracker("strcf"))
    performance = experiment.report(["strcf"])["strcf"]

    sequences = load_dataset("dtb70", root)
    run_one_pass(load_config("strcf"), sequences, tmp_path / "dcfkit", progress=False)
    for seq in sequences:
        written = np.loadtxt(tmp_path / "results" / "DTB70" / "strcf" / f"{seq.name}.txt", delimiter=",")
        ours = np.loadtxt(tmp_path / "dcfkit" / "strcf" / f"{seq.name}.txt", delimiter=",")
        assert written.shape == ours.shape == (12, 4)
        np.testing.assert_allclose(written, ours, rtol=0, atol=1e-3, err_msg=seq.name)

    overall = performance["overall"]
    assert 0 < overall["success_score"] <= 1 and 0 <= overall["precision_score"] <= 1 and overall["speed_fps"] > 0
    assert json.loads((tmp_path / "reports" / "DTB70" / "strcf" / "performance.json").read_text())["strcf"] \
        ["overall"]["success_score"] == overall["success_score"]
    scores = evaluate({"strcf": load_results(tmp_path / "dcfkit", "strcf", sequences)}, sequences,
                      protocol="pysot").overall[0]
    assert overall["success_score"] == pytest.approx(scores["auc"], abs=1e-12)
    assert overall["precision_score"] == pytest.approx(scores["precision"], abs=1e-12)


def test_experiment_on_uav123_10fps_writes_what_dcfkit_eval_writes(adapter, shared_data, tmp_path):
    """UAV123@10fps, which got10k's ExperimentUAV123 cannot load, through the adapter's
    Experiment: got10k's run and report on a dcfkit dataset, the result files dcfkit eval's."""
    root = shared_data / "UAV123_10fps"
    sequences = load_dataset("uav123_10fps", root, ["wakeboard7"])
    experiment = adapter.Experiment(sequences, "UAV123_10fps", result_dir=str(tmp_path / "results"),
                                    report_dir=str(tmp_path / "reports"))
    assert experiment.dataset.seq_names == ["wakeboard7"] and len(experiment.dataset) == 1
    files, anno = experiment.dataset["wakeboard7"]
    assert files[0] == str(sequences[0].frames[0]) and np.array_equal(anno, sequences[0].ground_truth + [1, 1, 0, 0])
    experiment.run(adapter.Tracker("kcf"))
    overall = experiment.report(["kcf"])["kcf"]["overall"]
    run_one_pass(load_config("kcf"), sequences, tmp_path / "dcfkit", progress=False)
    written = np.loadtxt(tmp_path / "results" / "UAV123_10fps" / "kcf" / "wakeboard7.txt", delimiter=",")
    ours = np.loadtxt(tmp_path / "dcfkit" / "kcf" / "wakeboard7.txt", delimiter=",")
    np.testing.assert_allclose(written, ours, rtol=0, atol=1e-3)
    scores = evaluate({"kcf": load_results(tmp_path / "dcfkit", "kcf", sequences)}, sequences,
                      protocol="pysot").overall[0]
    assert overall["success_score"] == pytest.approx(scores["auc"], abs=1e-12)
