"""The platform record (dcfkit.store.platforms): what it holds, in sidecars and reports, and the
warning of `dcfkit compare` and `dcfkit report` when result folders come from different platforms."""
import importlib.metadata
import json
import os
import subprocess
import sys

import numpy as np
import pytest
from test_evaluation import CONFIG, Counter, seqs  # noqa: F401  (seqs: a fixture)

from dcfkit import cli
from dcfkit.analysis.compare import compare_folders
from dcfkit.analysis.scoring import evaluate
from dcfkit.datasets import load_dataset
from dcfkit.store import platforms
from dcfkit.running.evaluation import run_one_pass
from dcfkit.store.results import load_results

RECORD = {"arch": "x86_64", "cpu": "Some CPU (cpu family 6, model 85)", "simd": "X86_V2 X86_V3",
          "blas": "openblas 0.3 Haswell", "libc": "glibc 2.36", "libraries": {"numpy": "2.4.6", "scipy": "1.17.1"},
          "switches": {}}


def test_record_names_this_process():
    rec = platforms.record()
    assert set(rec) == {"arch", "cpu", "simd", "blas", "libc", "libraries", "switches"}
    assert rec["libraries"]["numpy"] == np.__version__
    assert rec["libraries"]["simplejpeg"] == importlib.metadata.version("simplejpeg")  # it decodes JPEG frames
    assert rec["simd"] and rec["blas"] and rec["cpu"]
    assert json.loads(json.dumps(rec)) == rec  # it goes into JSON sidecars as it is


def test_record_sees_the_switches_of_another_platform():
    """numpy's dispatch limited to its baseline and OpenBLAS forced to another kernel show in the
    record (a fresh process: both are read when the libraries load)."""
    x86 = platforms.record()["arch"].lower() in ("x86_64", "amd64")
    env = {**os.environ, "OPENBLAS_CORETYPE": "Prescott"}
    if x86:  # numpy refuses to disable features it does not dispatch on this architecture
        env["NPY_DISABLE_CPU_FEATURES"] = "X86_V3 X86_V4 AVX512_ICL"
    out = subprocess.run([sys.executable, "-c", "import json; from dcfkit.store import platforms; "
                          "print(json.dumps(platforms.record()))"], env=env, capture_output=True, text=True, check=True)
    rec = json.loads(out.stdout)
    if x86:
        assert "X86_V3" not in rec["simd"].split()
        assert rec["blas"] != platforms.record()["blas"]  # OpenBLAS calls its SSE3 kernel Katmai
    assert rec["switches"]["OPENBLAS_CORETYPE"] == "Prescott"


def test_differences_and_description():
    other = {**RECORD, "blas": "openblas 0.3 SkylakeX", "libraries": {"numpy": "2.3.0", "scipy": "1.17.1"},
             "switches": {"OPENBLAS_CORETYPE": "SkylakeX"}}
    assert platforms.differences(RECORD, other) == [
        "blas: openblas 0.3 Haswell -> openblas 0.3 SkylakeX", "numpy: 2.4.6 -> 2.3.0", "OPENBLAS_CORETYPE: None -> SkylakeX"]
    assert platforms.differences(RECORD, dict(RECORD)) == []
    assert platforms.differences(RECORD, None) == []  # nothing recorded: nothing to compare
    assert platforms.describe(None) == "not recorded"
    line = platforms.describe(RECORD)
    assert "Some CPU" in line and "SIMD X86_V2 X86_V3" in line and "numpy 2.4.6" in line and "BLAS openblas 0.3 Haswell" in line


def _with_platform(folder, record):
    for sidecar in folder.glob("*.json"):
        meta = json.loads(sidecar.read_text())
        meta["platform"] = record
        sidecar.write_text(json.dumps(meta))


def test_sidecars_reports_and_compare_name_the_platform(tmp_path, seqs, capsys):  # noqa: F811
    for out in ("here", "there"):
        run_one_pass(CONFIG, seqs, tmp_path / out, make_tracker=Counter(), progress=False)
    here, there = tmp_path / "here" / "drift", tmp_path / "there" / "drift"
    assert json.loads((here / "a.json").read_text())["platform"] == platforms.record()
    res = compare_folders(here, there, seqs)
    assert res["platform_differences"] == [] and res["platforms"]["results"] == [platforms.describe(platforms.record())]

    _with_platform(there, RECORD)
    res = compare_folders(here, there, seqs)
    assert res["platforms"]["reference"] == [platforms.describe(RECORD)]
    assert res["platform_differences"] == sorted(platforms.differences(platforms.record(), RECORD))
    assert any(d.startswith("cpu: ") for d in res["platform_differences"])
    scores = evaluate({"here": load_results(tmp_path / "here", "drift", seqs),
                       "there": load_results(tmp_path / "there", "drift", seqs)}, seqs)
    assert scores.platforms["there"] == [[platforms.describe(RECORD), 3]]

    _with_platform(there, None)  # e.g. files made before platforms were recorded
    assert compare_folders(here, there, seqs)["platform_differences"] == []


def otb_layout(root, seqs):
    """The sequences as an OTB root (ROOT/<seq>/img/*.jpg, 1-based groundtruth_rect.txt)."""
    for seq in seqs:
        (root / seq.name / "img").mkdir(parents=True)
        for k, frame in enumerate(seq.frames):
            (root / seq.name / "img" / f"{k + 1:04d}.jpg").write_bytes(frame.read_bytes())
        boxes = seq.ground_truth + [1, 1, 0, 0]
        (root / seq.name / "groundtruth_rect.txt").write_text("".join(",".join(f"{v:g}" for v in b) + "\n" for b in boxes))
    return load_dataset("otb", root)


def test_compare_command_warns_about_different_platforms(tmp_path, seqs, capsys):  # noqa: F811
    root = tmp_path / "otb"
    otb = otb_layout(root, seqs)
    for out in ("here", "there"):
        run_one_pass(CONFIG, otb, tmp_path / out, make_tracker=Counter(), progress=False)
    _with_platform(tmp_path / "there" / "drift", RECORD)
    args = ["compare", str(tmp_path / "here" / "drift"), str(tmp_path / "there" / "drift"), "--dataset", "otb",
            "--root", str(root)]
    if cli.main(args) != 0:
        pytest.fail(capsys.readouterr().err)
    out, err = capsys.readouterr()
    assert "there/drift platform: " + platforms.describe(RECORD) in out  # one folder name: with its parent
    assert "warning: here/drift and there/drift come from different platforms (" in err and "cpu: " in err

    _with_platform(tmp_path / "there" / "drift", platforms.record())
    assert cli.main(args) == 0
    assert "different platforms" not in capsys.readouterr().err


def test_report_command_names_each_trackers_platform(tmp_path, seqs, capsys):  # noqa: F811
    root = tmp_path / "otb"
    otb = otb_layout(root, seqs)
    run_one_pass(CONFIG, otb, tmp_path / "out", make_tracker=Counter(), progress=False)
    run_one_pass({**CONFIG, "name": "elsewhere"}, otb, tmp_path / "out", make_tracker=Counter(), progress=False)
    _with_platform(tmp_path / "out" / "elsewhere", RECORD)
    assert cli.main(["report", str(tmp_path / "out"), "--dataset", "otb", "--root", str(root),
                     "--report-dir", str(tmp_path / "report")]) == 0
    out, err = capsys.readouterr()
    assert f"drift platform: {platforms.describe(platforms.record())}" in out
    assert f"elsewhere platform: {platforms.describe(RECORD)}" in out
    assert "warning: these results come from 2 platforms" in err
    saved = json.loads((tmp_path / "report" / "report.json").read_text())
    assert saved["platforms"]["elsewhere"] == [[platforms.describe(RECORD), 3]]


def test_the_blas_recorded_is_numpys_whichever_library_loaded_first(monkeypatch):
    """A worker that imports scipy or OpenCV first lists their BLAS first: the record must not
    change with it (eval --jobs 2 once warned of two platforms on one machine)."""
    from dcfkit.store import platforms

    numpy_blas = {"user_api": "blas", "internal_api": "openblas", "version": "0.3.31", "architecture": "Haswell",
                  "filepath": "/site-packages/numpy.libs/libscipy_openblas64_.so"}
    other_blas = {"user_api": "blas", "internal_api": "openblas", "version": "0.3.15", "architecture": "Haswell",
                  "filepath": "/usr/lib/libopenblas.so.0"}
    for order in ([numpy_blas, other_blas], [other_blas, numpy_blas]):
        monkeypatch.setattr(platforms, "threadpool_info", lambda order=order: order)
        assert platforms._blas() == "openblas 0.3.31 Haswell"
