"""A stored run stands for its sequence's data only: another benchmark folder's sequence of the
same name, length and first box is run again (eval, ablate and search share ResultStore.status)."""
from __future__ import annotations

import dataclasses
import json

import cv2
import numpy as np
from test_evaluation import CONFIG, Counter, gt_boxes, seqs  # noqa: F401  (seqs: a fixture)

from dcfkit.store import results
from dcfkit.running.evaluation import run_one_pass


def test_a_resume_on_other_data_of_the_same_names_runs_again(tmp_path, seqs, caplog):  # noqa: F811
    run_one_pass(CONFIG, seqs, tmp_path, make_tracker=Counter(), progress=False)
    moved = gt_boxes()
    moved[-1, 0] += 3  # the same name, length and first box; a later box differs
    other = dataclasses.replace(seqs[0], ground_truth=moved)
    again = Counter()
    with caplog.at_level("WARNING"):
        summary = run_one_pass(CONFIG, [other, *seqs[1:]], tmp_path, make_tracker=again, progress=False)
    assert summary["done"] == ["a"] and summary["skipped"] == ["b", "c"] and again.made == 1
    assert "recomputing 1 result(s) made on other data" in caplog.text
    noise = np.random.default_rng(0).integers(0, 255, (16, 16, 3), np.uint8)
    cv2.imwrite(str(seqs[1].frames[3]), noise)  # a frame of another size
    assert run_one_pass(CONFIG, [other, *seqs[1:]], tmp_path, make_tracker=Counter(), progress=False)["done"] == ["b"]


def test_the_identity_is_the_data_not_the_folder_and_old_sidecars_are_trusted(tmp_path, seqs):  # noqa: F811
    copy = tmp_path / "copy"
    copy.mkdir()
    frames = [copy / f.name for f in seqs[2].frames]
    for source, target in zip(seqs[2].frames, frames):
        target.write_bytes(source.read_bytes())
    assert results.data_identity(dataclasses.replace(seqs[2], frames=tuple(frames))) == results.data_identity(seqs[2])
    run_one_pass(CONFIG, seqs, tmp_path, make_tracker=Counter(), progress=False)
    sidecar = tmp_path / "drift" / "a.json"
    meta = json.loads(sidecar.read_text())
    del meta["data_identity"]  # as dcfkit <= 0.9.0 wrote it
    sidecar.write_text(json.dumps(meta))
    moved = gt_boxes()
    moved[-1, 0] += 3
    other = dataclasses.replace(seqs[0], ground_truth=moved)
    assert run_one_pass(CONFIG, [other], tmp_path, make_tracker=Counter(), progress=False)["skipped"] == ["a"]


def test_the_identity_ignores_a_last_bit_of_the_ground_truth():
    """vot_area's boxes come from np.linalg.norm, whose last bit may differ between BLAS builds:
    one machine's results must not read as other data on another."""
    from dcfkit.datasets import Sequence

    gt = np.array([[10.1, 20.2, 30.3, 40.4], [11.1, 21.2, 31.3, 41.4]])
    nudged = np.nextafter(gt, np.inf)
    moved = gt.copy()
    moved[1, 0] += 0.01  # a correction
    same, other, corrected = (Sequence("s", ("0.jpg", "1.jpg"), g) for g in (gt, nudged, moved))
    assert not np.array_equal(gt, nudged)
    assert results.data_identity(same) == results.data_identity(other) != results.data_identity(corrected)
