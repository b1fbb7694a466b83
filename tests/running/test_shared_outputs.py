"""Result folders and reports are shared: what dcfkit writes into them names no host, working
directory or home folder, and paths in a report are relative to it; the platform facts that
reproducing a result needs stay."""
from __future__ import annotations

import json
import os
import platform
import re
from pathlib import Path

from test_evaluation import CONFIG, Counter, seqs  # noqa: F401  (seqs: a fixture)

from dcfkit.analysis import report
from dcfkit.analysis.report_html import write_html_report
from dcfkit.store import provenance
from dcfkit.running.evaluation import run_one_pass
from dcfkit.store.provenance import running_command, without_home

HOST = "alices-laptop.example"


def test_nothing_personal_in_sidecars_and_reports(tmp_path, seqs, monkeypatch):  # noqa: F811
    monkeypatch.setenv("HOME", str(tmp_path))  # the frames lie in the user's home: tmp_path/data
    monkeypatch.setattr(platform, "node", lambda: HOST)
    provenance.machine.cache_clear()
    (tmp_path / "project").mkdir()
    monkeypatch.chdir(tmp_path / "project")
    out = tmp_path / "project" / "out"
    with running_command(["dcfkit", "eval", "drift.yaml", "--root", str(tmp_path / "data"), "--out", str(out)]):
        run_one_pass(CONFIG, seqs, out, make_tracker=Counter(), progress=False)
        failed = run_one_pass({"name": "broken"}, seqs[:1], out, make_tracker=Counter({1: (2, ValueError)}),
                              progress=False)
    assert failed["failed"]
    monkeypatch.setattr(report, "plot_curves", lambda *a, **k: [])  # matplotlib's figures: most of the time, no text
    _, paths = write_html_report(out, seqs, trackers=["drift"])
    provenance.machine.cache_clear()
    written = [p for p in (*out.rglob("*"), *paths) if p.is_file() and ".locks" not in p.parts]
    assert {p.name for p in written} >= {"a.json", "a.error", "report.html", "report.json"}
    for path in written:
        text = path.read_bytes().decode("utf-8", "replace")
        for personal in (HOST, str(tmp_path), os.getcwd()):
            assert personal not in text, f"{path.name} holds {personal}"
    meta = json.loads((out / "drift" / "a.json").read_text())
    assert meta["command"] == ["dcfkit", "eval", "drift.yaml", "--root", "~/data", "--out", "~/project/out"]
    assert {"cpu", "cores", "system", "python"} <= set(meta["machine"]) and meta["platform"]["blas"]
    error = json.loads((out / "broken" / "a.error").read_text())
    assert error["frame_file"] == "~/data/a/00003.jpg"
    html = next(p for p in paths if p.name == "report.html").read_text()
    data = json.loads(re.search(r'<script type="application/json" id="report-data">(.*?)</script>', html, re.S)[1])
    section, = [s for s in data["sections"] if s["kind"] == "provenance"]
    assert [t["folder"] for t in section["trackers"]] == ["../out/drift"]  # from out_report/, beside out/


def test_the_home_folder_is_written_as_a_tilde(monkeypatch):
    monkeypatch.setenv("HOME", "/home/al")
    assert without_home("/home/al/data and /home/alice/data, /home/al") == "~/data and /home/alice/data, ~"
    monkeypatch.setenv("HOME", "/")
    assert without_home("/data") == "/data"
    assert str(Path("~").expanduser()) == "/"
