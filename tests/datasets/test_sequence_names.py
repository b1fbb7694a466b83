"""Sequence names are checked where every layout passes, its loader (dcfkit.datasets.layout):
results, exports and reports are files named after them, so a name must be one safe, UTF-8
file name, and unique in its dataset."""
from __future__ import annotations

import os
import shutil
import sys

import cv2
import numpy as np
import pytest
from test_ablation import write_otb
from test_layouts import install

from dcfkit import cli
from dcfkit import registry as reg
from dcfkit.datasets import DatasetError, Sequence, load_dataset, registered_layout
from dcfkit.datasets.layout import NAME_BYTES, new_layout, sequence_name_problem


def toys(*names, annotation=None) -> list[Sequence]:
    return [Sequence(n, ("0.jpg",), [[1, 1, 4, 4]], {}, "toys", annotation) for n in names]


@pytest.mark.parametrize("name, said", [
    ("../../X", "holds / \\ or :"), ("a/b", "holds / \\ or :"), ("a\\b", "holds / \\ or :"), ("C:x", "holds /"),
    ("..", "is not a file name"), (".", "is not a file name"), ("", "is not a file name"), (".a", "starts with '.'"),
    ("a\x00b", "unprintable"), ("a\nb", "line break"), ("a\tb", "tab"), (" a", "starts or ends with a space"),
    ("a ", "starts or ends with a space"), ("x" * (NAME_BYTES + 1), f"at most {NAME_BYTES}"),
    ("seq\udcff", "is not valid UTF-8"), (7, "is a int, not a string"),
])
def test_a_layout_returning_an_unsafe_name_is_refused_naming_the_layout_and_the_name(tmp_path, name, said):
    with registered_layout("unsafe_toys", lambda root, sequences=None: toys("ok", name), "ROOT/<seq>"):
        with pytest.raises(DatasetError) as info:
            load_dataset("unsafe_toys", tmp_path)
    message = str(info.value)
    assert message.startswith("dataset layout 'unsafe_toys': sequence name ") and said in message
    assert "\n" not in message and "\udcff" not in message and message.isprintable()


def test_names_that_real_benchmarks_use_are_taken():
    for name in ("Jogging.1", "car1_s", "airplane-1", "GOT-10k_Val_000001", "bike 3", "名前", "x" * NAME_BYTES,
                 "zebra\u00a0x", "東京\u3000駅", "straße"):  # str.isprintable refused the no-break and ideographic spaces
        assert sequence_name_problem(name) is None, name


def test_names_that_only_casefold_alike_are_two(tmp_path):
    with registered_layout("german", lambda root, sequences=None: toys("straße", "strasse"), "ROOT/<seq>"):
        assert [s.name for s in load_dataset("german", tmp_path)] == ["straße", "strasse"]  # no disk takes them as one


def test_names_must_be_unique_even_in_case(tmp_path):
    for names, other in ((("a", "b", "a"), "'a'"), (("Car1", "car1"), "'Car1'")):
        with registered_layout("twice", lambda root, sequences=None: toys(*names), "ROOT/<seq>"):
            with pytest.raises(DatasetError, match=f"dataset layout 'twice': sequence name .* is also the name of "
                                                   f"sequence {other}"):
                load_dataset("twice", tmp_path)


def test_a_loader_must_return_a_list_of_sequences(tmp_path):
    with registered_layout("lazy", lambda root, sequences=None: (s for s in toys("a")), "ROOT/<seq>"):
        with pytest.raises(DatasetError, match=r"dataset layout 'lazy': load\(\) returned <generator .*expected a "
                                               r"list of dcfkit.datasets.Sequence"):
            load_dataset("lazy", tmp_path)


def test_a_plugins_layout_is_checked_and_named_with_its_plugin(tmp_path):
    registry = reg.Registry(make_layout=new_layout)
    registry._provider = "evil (evil:plugin)"  # as _run_plugin sets it while the plugin registers
    layout = registry.register_dataset("evil", lambda root, sequences=None: toys("../../X"), "ROOT/<seq>")
    with pytest.raises(DatasetError, match=r"^dataset layout 'evil' \(from evil \(evil:plugin\)\): sequence name "
                                           r"'\.\./\.\./X' holds / \\ or :"):
        layout.load(tmp_path)


PLUGIN = '''
from dcfkit.datasets import Sequence
from dcfkit.registry import hookimpl

def load(root, sequences=None):
    frames = sorted(root.glob("*.jpg"))
    return [Sequence("../../X", frames, [[2, 2, 8, 8]] * len(frames), {}, "escape")]

@hookimpl
def dcfkit_register_components(registry):
    registry.register_dataset("escape", load, "ROOT/*.jpg")
'''


def test_eval_with_a_plugins_name_that_climbs_out_writes_nothing(tmp_path, monkeypatch, capsys):
    install(monkeypatch, {"dcfkit_test_escape": PLUGIN})
    root = tmp_path / "a" / "b" / "data"
    root.mkdir(parents=True)
    for k in range(3):
        cv2.imwrite(str(root / f"{k}.jpg"), np.full((24, 32, 3), 40 * k, np.uint8))
    out = tmp_path / "a" / "b" / "out"
    assert cli.main(["eval", "kcf", "--dataset", "escape", "--root", str(root), "--out", str(out),
                     "--no-progress"]) == 2
    said = capsys.readouterr().err
    assert "dataset layout 'escape' (from dcfkit_test_escape" in said and "'../../X' holds /" in said
    assert sorted(p.name for p in tmp_path.rglob("*") if p.suffix != ".jpg") == ["a", "b", "data"]


@pytest.mark.skipif(sys.platform != "linux", reason="a folder name of any bytes needs a Linux file system")
def test_a_folder_name_that_is_not_utf8_stops_eval_before_any_work(tmp_path, capsys):
    root = tmp_path / "data"
    write_otb(root, "fine", seed=1, n_frames=3)
    shutil.copytree(root / "fine", root / os.fsdecode(b"seq\xff"))  # not cv2: it crashes on such a path
    out = tmp_path / "out"
    assert cli.main(["eval", "kcf", "--dataset", "otb", "--root", str(root), "--out", str(out),
                     "--no-progress"]) == 2
    said = capsys.readouterr().err
    assert "dataset layout 'otb': sequence name b'seq\\xff' (" in said and "rename" in said
    assert said.count("\n") == 1 and not out.exists()
    shutil.rmtree(root / os.fsdecode(b"seq\xff"))  # renamed away: eval runs
    assert cli.main(["eval", "kcf", "--dataset", "otb", "--root", str(root), "--out", str(out), "--no-progress"]) == 0
