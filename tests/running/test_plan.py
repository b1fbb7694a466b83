"""The run plan of eval, ablate and search (dcfkit/running/plan.py): a run shared by entries of
one run key is tracked once and copied, claims over many folders hold one lock, folder names
are usable and distinct, and eval's TRE runs get their page from `report --html`."""
from __future__ import annotations

import json
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from test_ablation import write_otb
from test_evaluation import CONFIG, Counter, seqs  # noqa: F401  (seqs: a fixture)

from dcfkit import cli
from dcfkit.datasets import load_dataset
from dcfkit.errors import DcfkitError
from dcfkit.running.evaluation import run_one_pass
from dcfkit.running.layout import MAX_NAME_BYTES, folder_names, folder_problem
from dcfkit.running.plan import Entry, RunPlan
from dcfkit.store.claims import claimed, claimed_folders
from dcfkit.store.provenance import run_key

RESULT_ENDS = (".txt", ".time", ".confidence", ".json")


def result_files(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir()) if p.is_file()}


def test_entries_of_one_run_key_track_each_run_once_and_each_folder_holds_it(tmp_path, seqs):  # noqa: F811
    made = Counter()
    entries = [Entry("one", CONFIG, made), Entry("two", {**CONFIG, "name": "renamed"}, made)]  # one key: names change no box
    plan = RunPlan(entries, seqs, "ope", tmp_path).run("dcfkit ablate")
    assert made.made == len(seqs)  # not twice
    assert [p.outcome()["done"] for p in plan.entries] == [["a", "b", "c"]] * 2
    one, two = result_files(tmp_path / "one"), result_files(tmp_path / "two")
    assert one == two and set(one) == {f"{s.name}{end}" for s in seqs for end in RESULT_ENDS}
    assert json.loads(one["a.json"])["run_key"] == run_key(CONFIG)
    # an entry added later gets the runs another entry of its key holds: copied, not tracked
    plan = RunPlan([*entries, Entry("three", CONFIG, made)], seqs, "ope", tmp_path).run("dcfkit ablate")
    assert made.made == len(seqs) and not plan.tracked and plan.entries[2].done == ["a", "b", "c"]
    assert result_files(tmp_path / "three") == one
    # another factory is another run, whatever the key
    other = Counter()
    RunPlan([*entries, Entry("four", CONFIG, other)], seqs, "ope", tmp_path).run("dcfkit ablate")
    assert made.made == len(seqs) and other.made == len(seqs)


def test_a_shared_run_that_fails_fails_in_every_entry_and_is_retried_once(tmp_path, seqs):  # noqa: F811
    failing = Counter({1: (2, ValueError)})  # the first tracker raises on frame 3
    entries = [Entry("one", CONFIG, failing), Entry("two", CONFIG, failing)]
    plan = RunPlan(entries, seqs[:1], "ope", tmp_path).run("dcfkit ablate")
    assert failing.made == 1 and [list(p.failed) for p in plan.entries] == [["a"], ["a"]]
    for name in ("one", "two"):
        assert set(result_files(tmp_path / name)) == {"a.error"}
    again = RunPlan(entries, seqs[:1], "ope", tmp_path).run("dcfkit ablate")
    assert failing.made == 2 and [p.done for p in again.entries] == [["a"], ["a"]]
    assert result_files(tmp_path / "one") == result_files(tmp_path / "two")  # the error gone from both


def test_claims_of_many_folders_hold_one_lock_and_refuse_the_same_runs(tmp_path):
    pytest.importorskip("fcntl", reason="POSIX file locks")
    folders = [tmp_path / f"v{i}" for i in range(5)]
    for folder in folders:
        folder.mkdir()
    with claimed_folders({f: (["a", "b"], lambda name, f=f: f"{f.name}'s {name}") for f in folders}, "dcfkit ablate"):
        locks = [next((f / ".locks").glob("*.lock")) for f in folders]
        assert len({lock.stat().st_ino for lock in locks}) == 1  # one file, linked into each folder
        with pytest.raises(DcfkitError, match=r"another `dcfkit eval` is writing v3's b"):
            with claimed(folders[3], ["b"], "dcfkit eval", lambda name: f"v3's {name}"):
                pass
        with claimed(folders[3], ["c"], "dcfkit eval", str):  # other runs of the folder go on alongside
            pass
    assert not [p for f in folders for p in (f / ".locks").iterdir() if p.name != ".guard"]


def test_an_ablation_of_many_variants_runs_within_64_open_files(tmp_path):
    """200 variants: a lock each would take 200 open files ("Too many open files")."""
    script = textwrap.dedent(f"""
        import json, resource, sys
        import cv2, numpy as np
        sys.path.insert(0, {str(Path(__file__).parent)!r})
        from test_evaluation import Counter
        from dcfkit.datasets import Sequence
        from dcfkit.running.plan import Entry, RunPlan
        root = __import__("pathlib").Path({str(tmp_path)!r})
        frames = [root / f"f{{k}}.jpg" for k in range(2)]
        for f in frames:
            cv2.imwrite(str(f), np.full((32, 32, 3), 9, np.uint8))
        seqs = [Sequence("s", tuple(frames), np.array([[8.0, 8, 10, 10]] * 2), {{}}, "fake")]
        resource.setrlimit(resource.RLIMIT_NOFILE, (64, 64))
        made = Counter()
        entries = [Entry(f"v{{i}}", {{"name": "drift", "drift": float(i % 2)}}, made) for i in range(200)]
        plan = RunPlan(entries, seqs, "ope", root / "out").run("dcfkit ablate")
        print(json.dumps([made.made, sum(len(p.done) for p in plan.entries)]))
    """)
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    assert json.loads(done.stdout.splitlines()[-1]) == [2, 200] and "running without it" not in done.stderr


def test_folder_names_are_the_labels_where_usable_and_distinct_otherwise():
    labels = ["full", "mu=0.1", "mu=0.1, theta=4", "a/b", "a_b", "A_B", ".hidden", "x" * 300, "configs", "line\nbreak"]
    names = folder_names(labels, reserved=("configs", "summary.md"))
    assert names["full"] == "full" and names["mu=0.1"] == "mu=0.1"  # usable: kept
    assert names["mu=0.1, theta=4"] == "mu=0.1_theta=4"  # no comma: report --trackers splits on it
    assert names[".hidden"] == "hidden" and names["line\nbreak"] == "line_break"
    assert names["a/b"].startswith("a_b-") and names["a_b"].startswith("a_b-")  # taken (case aside): a digest
    assert names["A_B"] == "A_B"  # of labels alike but for case, the first in code point order keeps its name
    assert names["configs"].startswith("configs-")  # reserved
    assert all(folder_problem(n) is None for n in names.values())
    assert len({n.casefold() for n in names.values()}) == len(labels)
    assert len(names["x" * 300].encode()) <= MAX_NAME_BYTES
    assert folder_names(reversed(labels), reserved=("configs", "summary.md")) == names  # the order changes no name


def test_eval_tre_runs_get_their_html_page_from_report(tmp_path):
    """An eval's TRE runs need no ablation to be seen: `report --experiment tre --html` writes the page."""
    for i, name in enumerate(("seqA", "seqB")):
        write_otb(tmp_path / "data", name, seed=i, n_frames=22)
    seqs = load_dataset("otb", tmp_path / "data")
    for drift in (1.0, 2.0):
        run_one_pass({"name": f"drift{drift:g}", "drift": drift}, seqs, tmp_path / "out", make_tracker=Counter(),
                     progress=False, experiment="tre")
    assert cli.main(["report", str(tmp_path / "out"), "--dataset", "otb", "--root", str(tmp_path / "data"),
                     "--experiment", "tre", "--html"]) == 0
    page = (tmp_path / "out_report" / "tre" / "report.html").read_text(encoding="utf-8")
    assert "TRE" in page and "drift1" in page and "drift2" in page
    scored = json.loads((tmp_path / "out_report" / "tre" / "report.json").read_text())
    assert sorted(r["tracker"] for r in scored["overall"]) == ["drift1", "drift2"]
