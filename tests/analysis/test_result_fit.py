"""Results that do not fit the sequences of a report: one message naming whose, and why."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from dcfkit.analysis.result_fit import check_results_fit
from dcfkit.datasets import DatasetError, Sequence


def sequence(name: str, n: int = 10) -> Sequence:
    return Sequence(name, tuple(Path(f"{k}.jpg") for k in range(n)), np.ones((n, 4)), {}, "t")


def results(folder: Path, name: str, frames: int | None = None, command: list | None = None) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    (folder / f"{name}.txt").write_text("1,1,1,1\n" * (frames or 1))
    if frames is not None:
        record = {"frames": frames, **({} if command is None else {"command": command})}
        (folder / f"{name}.json").write_text(json.dumps(record))
    return folder


def test_a_tracker_without_a_result_of_these_sequences_is_named_when_it_would_leave_none(tmp_path):
    folders = {"a": results(tmp_path / "a", "seqA"), "b": results(tmp_path / "b", "seqZ"),
               "c": tmp_path / "c"}
    folders["c"].mkdir()
    with pytest.raises(DatasetError, match=r"^the results of b, c are of other sequences than the 1 scored here "
                                           r"\(seqA\): they are of seqZ; .* or leave those trackers out"):
        check_results_fit(tmp_path, folders, [sequence("seqA")], "skip")
    check_results_fit(tmp_path, folders, [sequence("seqA")], "fail")  # scored as failures, as asked
    with pytest.raises(DatasetError, match=r"^the results in .*: no result file \(<sequence>.txt\) in .*c$"):
        check_results_fit(tmp_path, {"c": folders["c"]}, [sequence("seqA")], "fail")


def test_a_cut_is_read_from_the_command_else_from_the_frame_counts(tmp_path):
    runs = [sequence("seqA"), sequence("seqB", 12)]
    for name in ("seqA", "seqB"):
        results(tmp_path / "old", name, 4)  # no command recorded: 4 frames of each longer run
        results(tmp_path / "new", name, 4 if name == "seqA" else 3, ["dcfkit", "eval", "--max-frames=4"])
    for tracker in ("old", "new"):
        with pytest.raises(DatasetError, match=rf"^the results of {tracker} in .* were cut by --max-frames 4 \(their "
                                               r"runs of seqA, seqB hold at most 4 frames\) and this report has no "
                                               r"--max-frames: report them with --max-frames 4$"):
            check_results_fit(tmp_path, {tracker: tmp_path / tracker}, runs)
    results(tmp_path / "mixed", "seqA", 10)  # one whole run: the others' warnings say what is wrong
    results(tmp_path / "mixed", "seqB", 4)
    check_results_fit(tmp_path, {"mixed": tmp_path / "mixed"}, runs)
    results(tmp_path / "odd", "seqA", 4)  # two lengths, no command: no single cut to name
    results(tmp_path / "odd", "seqB", 5)
    check_results_fit(tmp_path, {"odd": tmp_path / "odd"}, runs)
