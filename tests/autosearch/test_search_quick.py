"""``dcfkit search --sequences/--max-frames`` and the quick try of docs/search.md.

The documented command runs here on synthetic sequences of the documented names (the spec's
dataset swapped for the OTB layout, its config paths for the shipped names), so that the test
needs no benchmark data and stays fast."""
from __future__ import annotations

import dataclasses
import json
import re
import shlex
from pathlib import Path

import pytest
from test_ablation import write_otb

from dcfkit import cli
from dcfkit.autosearch import Search, load_search_spec
from dcfkit.autosearch.evaluation import Evaluator
from dcfkit.cli.parser import build_parser
from dcfkit.config import load_config
from dcfkit.datasets import DatasetError, load_dataset
from dcfkit.errors import DcfkitError

pytest.importorskip("optuna")

ROOT = Path(__file__).resolve().parents[2]


def documented_command() -> list[str]:
    """The arguments of the quick try's `dcfkit search` in docs/search.md, as the shell splits them."""
    text = (ROOT / "docs" / "search.md").read_text(encoding="utf-8")
    (line,) = re.findall(r"^dcfkit search quick .*$", text, re.MULTILINE)
    return shlex.split(line)[2:]  # after "dcfkit search"


def option(argv: list[str], name: str) -> str:
    return argv[argv.index(name) + 1]


@pytest.fixture
def quick(tmp_path):
    """The documented argv, its spec (as a synthetic OTB folder's) and its sequences, 3 frames
    each (DR²Track takes ~10 ms a frame: 24 runs of 30 frames would take seconds)."""
    argv = documented_command()
    spec = (ROOT / "configs" / "searches" / "quick.yaml").read_text(encoding="utf-8")
    spec = re.sub(r"(?ms)^dataset:.*?(?=^base:)", "dataset: {name: otb, root: data}\n", spec)
    spec = spec.replace("../dr2track.yaml", "dr2track").replace("../strcf.yaml", "strcf")
    (tmp_path / "quick.yaml").write_text(spec, encoding="utf-8")
    for i, name in enumerate(option(argv, "--sequences").split(",")):
        write_otb(tmp_path / "data", name, seed=i, n_frames=3)
    argv[argv.index("quick")] = str(tmp_path / "quick.yaml")
    argv[argv.index("--root") + 1] = str(tmp_path / "data")
    argv[argv.index("--out") + 1] = str(tmp_path / "out")
    argv[argv.index("--jobs") + 1] = "1"  # in this process: no pool to start
    return argv


def test_the_documented_quick_try_parses_as_documented():
    args = build_parser().parse_args(["search", *documented_command()])
    assert args.spec == "quick" and args.max_frames == 30
    assert args.sequences == "boat1,building4,wakeboard7,wakeboard10"
    assert (ROOT / "configs" / "searches" / "quick.yaml").is_file()


def test_the_documented_quick_try_runs_and_records_its_options(tmp_path, quick, capsys):
    assert cli.main(["search", *quick]) == 0
    out = tmp_path / "out"
    record = json.loads((out / "search.json").read_text())["fingerprint"]
    assert record["max_frames"] == 30 and record["sequences"] == ["boat1", "building4", "wakeboard10", "wakeboard7"]
    assert json.loads((out / "summary.json").read_text())["max_frames"] == 30
    assert "first 30 frames only (--max-frames 30" in (out / "summary.md").read_text()
    capsys.readouterr()
    for changed, message in ((["--max-frames", "20"], "made with --max-frames 30, this search has --max-frames 20"),
                             (["--sequences", "boat1,building4,wakeboard7"],
                              "made with --sequences 'boat1,building4,wakeboard10,wakeboard7', this search has "
                              "--sequences 'boat1,building4,wakeboard7'")):
        argv = list(quick)
        argv[argv.index(changed[0]) + 1] = changed[1]
        assert cli.main(["search", *argv]) != 0
        err = capsys.readouterr().err
        assert message in err and "a new --out for a separate search" in err and "\n" not in err.strip()
    argv = list(quick)
    argv[argv.index("--sequences") + 1] = "wakeboard10,boat1,wakeboard7,building4"  # the same, in another order
    assert cli.main(["search", *argv]) == 0  # resumed: every trial recorded, nothing run


def test_a_search_without_max_frames_resumes_one_recorded_before_the_option(tmp_path, quick):
    spec = load_search_spec(quick[0], root=tmp_path / "data")
    (tmp_path / "out").mkdir()
    Search(spec, tmp_path / "out").check_record()
    path = tmp_path / "out" / "search.json"
    record = json.loads(path.read_text())
    for key in ("max_frames", "sequences"):  # as dcfkit wrote it before
        del record["fingerprint"][key]
    path.write_text(json.dumps(record))
    Search(spec, tmp_path / "out").check_record()  # no error: whole sequences, the same ones
    cut = Search(dataclasses.replace(spec, max_frames=2), tmp_path / "out")
    path.write_text(json.dumps(record))
    with pytest.raises(DcfkitError, match=r"--max-frames \(not given: whole sequences\), this search has "
                                          r"--max-frames 2"):
        cut.check_record()


def test_cut_runs_are_never_taken_for_whole_ones_nor_replace_them(tmp_path):
    for i, name in enumerate(("seqA", "seqB")):
        write_otb(tmp_path / "data", name, seed=i, n_frames=5)
    whole = load_dataset("otb", tmp_path / "data")
    cut = [s.head(3) for s in whole]
    config = load_config("kcf")
    Evaluator(tmp_path / "cut", "otb", cut, ["ope"], jobs=1).scores(config, ["seqA", "seqB"])
    runs = sorted((tmp_path / "cut").glob("runs/*/*.json"))
    assert [json.loads(p.read_text())["frames"] for p in runs] == [3, 3]
    evaluator = Evaluator(tmp_path / "cut", "otb", whole, ["ope"], jobs=1)  # the same store, whole sequences
    evaluator.run([config], ["seqA", "seqB"])  # the cut runs are not taken: the whole ones are made
    assert [json.loads(p.read_text())["frames"] for p in runs] == [5, 5]
    before = {p: p.read_bytes() for p in runs}
    with pytest.raises(DatasetError, match=r"holds an intact run of 5 frames and this run of 'seqA' has 3"):
        Evaluator(tmp_path / "cut", "otb", cut, ["ope"], jobs=1).run([config], ["seqA", "seqB"])
    assert {p: p.read_bytes() for p in runs} == before
