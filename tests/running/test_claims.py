"""The claims that keep two evaluations from writing one run: a fixed number of open files
whatever the number of runs, a live claim refuses, a killed one's lapses (issue 37)."""
from __future__ import annotations

import json
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from test_evaluation import CONFIG, Counter, seqs  # noqa: F401  (seqs: a fixture)

from dcfkit.errors import DcfkitError
from dcfkit.store.claims import claimed
from dcfkit.running.evaluation import run_one_pass

pytest.importorskip("fcntl", reason="POSIX file locks")
HERE = Path(__file__).parent


def test_sre_on_many_sequences_runs_within_64_open_files(tmp_path):
    """10 sequences x 12 SRE runs: one lock a run took 120 open files ("Too many open files")."""
    script = textwrap.dedent(f"""
        import json, resource, sys
        import cv2, numpy as np
        sys.path.insert(0, {str(HERE)!r})
        from test_evaluation import Counter
        from dcfkit.datasets import Sequence
        from dcfkit.running.evaluation import run_one_pass
        root = __import__("pathlib").Path({str(tmp_path)!r})
        seqs = []
        for i in range(10):
            frames = [root / f"s{{i}}_{{k}}.jpg" for k in range(2)]
            for f in frames:
                cv2.imwrite(str(f), np.full((32, 32, 3), 9 * i, np.uint8))
            seqs.append(Sequence(f"s{{i}}", tuple(frames), np.array([[8.0, 8, 10, 10]] * 2), {{}}, "fake"))
        resource.setrlimit(resource.RLIMIT_NOFILE, (64, 64))
        summary = run_one_pass({{"name": "drift"}}, seqs, root / "out", make_tracker=Counter(), progress=False,
                               experiment="sre")
        print(json.dumps([len(summary["done"]), len(summary["failed"])]))
    """)
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    assert json.loads(done.stdout.splitlines()[-1]) == [120, 0] and "running without it" not in done.stderr


def test_a_live_claim_refuses_the_same_runs_and_a_killed_one_lapses(tmp_path, seqs):  # noqa: F811
    folder = tmp_path / "drift"
    folder.mkdir()
    with claimed(folder, ["b"], "dcfkit eval", str):
        with pytest.raises(DcfkitError, match=r"another `dcfkit eval` is writing drift's results of sequence 'b' to "
                                              r".*drift \(it holds .*\.lock\); wait for it or write elsewhere"):
            run_one_pass(CONFIG, seqs, tmp_path, make_tracker=Counter(), progress=False)
        assert not list(folder.glob("*.txt"))  # nothing was run
        assert run_one_pass(CONFIG, [seqs[0]], tmp_path, make_tracker=Counter(), progress=False)["done"] == ["a"]
    killed = ("import os, signal, sys; from dcfkit.store.claims import claimed\n"
              "with claimed(sys.argv[1], ['b', 'c'], 'dcfkit eval', str): os.kill(os.getpid(), signal.SIGKILL)")
    assert subprocess.run([sys.executable, "-c", killed, str(folder)], timeout=120).returncode == -9
    assert len(list((folder / ".locks").glob("*.claims"))) == 1  # left by the killed run
    assert run_one_pass(CONFIG, seqs, tmp_path, make_tracker=Counter(), progress=False)["done"] == ["b", "c"]
    assert sorted(p.name for p in (folder / ".locks").iterdir()) == [".guard"]  # nothing left once it ended


def test_a_stray_entry_in_the_locks_never_turns_claims_off(tmp_path, caplog):
    """A folder where an owner's lock goes (or a lock that cannot be read) made every evaluation run
    unclaimed, with a warning naming its own lock: two evaluations then wrote the same runs."""
    locks = tmp_path / ".locks"
    (locks / "stray.lock").mkdir(parents=True)
    (locks / "stray.claims").write_text('["a"]')
    with caplog.at_level("WARNING"):
        with claimed(tmp_path, ["b"], "dcfkit eval", str):  # claims nothing of it: runs, claimed
            assert len(list(locks.glob("*.claims"))) == 2
            with pytest.raises(DcfkitError, match="another `dcfkit eval` is writing b"):
                with claimed(tmp_path, ["b"], "dcfkit eval", str):
                    pass
        with pytest.raises(DcfkitError, match=r"stray\.claims claims a, and its lock .*stray\.lock cannot be read "
                                              r"\(Is a directory\): if no `dcfkit eval` writes there, remove both"):
            with claimed(tmp_path, ["a"], "dcfkit eval", str):
                pass
    assert "running without it" not in caplog.text
