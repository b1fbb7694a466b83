"""TRE, SRE and reset-based runs through `run_one_pass`, `dcfkit eval`, `report` and `ablate`:
where they are stored, that they resume (after kill -9 too), and how they are scored."""
from __future__ import annotations

import json
import signal
import subprocess
import sys
import time

import cv2
import numpy as np
import pytest
from test_ablation import write_otb, write_spec
from test_evaluation import Counter

from dcfkit import cli
from dcfkit.ablation import load_spec
from dcfkit.datasets import DatasetError, Sequence, load_dataset, read_boxes
from dcfkit.errors import ConfigError
from dcfkit.experiments.otb import sre_box, tre_starts
from dcfkit.running.evaluation import run_one_pass

N = 25


@pytest.fixture
def seqs(tmp_path):
    out = []
    for name in "ab":
        folder = tmp_path / "data" / name
        folder.mkdir(parents=True)
        frames = []
        for k in range(N):
            frames.append(folder / f"{k + 1:05d}.jpg")
            cv2.imwrite(str(frames[-1]), np.full((40, 50, 3), 5 * k, np.uint8))
        gt = np.array([[2.0 + k, 3, 6, 7] for k in range(N)])
        out.append(Sequence(name, tuple(frames), gt, {}, "fake"))
    return out


CONFIG = {"name": "drift", "drift": 1.0}


def test_tre_runs_are_stored_per_run_and_resume(tmp_path, seqs):
    made = Counter()
    summary = run_one_pass(CONFIG, seqs, tmp_path / "out", make_tracker=made, progress=False, experiment="tre")
    folder = tmp_path / "out" / "drift" / "tre"
    starts = tre_starts(seqs[0].ground_truth)
    assert summary["dir"] == folder and len(summary["done"]) == made.made == 2 * len(starts)
    assert summary["done"][:2] == ["a_001", "a_002"]
    for k, start in enumerate(starts, 1):
        meta = json.loads((folder / f"b_{k:03d}.json").read_text())
        assert meta["frames"] == N - start and meta["init_box"] == seqs[1].ground_truth[start].tolist()
        assert len(read_boxes(folder / f"b_{k:03d}.txt")) == N - start
    assert not list((tmp_path / "out" / "drift").glob("*.txt"))  # one-pass results stay apart
    again = run_one_pass(CONFIG, seqs, tmp_path / "out", make_tracker=made, progress=False, experiment="tre")
    assert again["done"] == [] and len(again["skipped"]) == 2 * len(starts) and made.made == 2 * len(starts)


def test_sre_runs_start_from_the_shifted_boxes(tmp_path, seqs):
    run_one_pass(CONFIG, seqs[:1], tmp_path / "out", make_tracker=Counter(), progress=False, experiment="sre")
    folder = tmp_path / "out" / "drift" / "sre"
    first = seqs[0].ground_truth[0]
    assert json.loads((folder / "a_009.json").read_text())["init_box"] == sre_box(first, "scale_8", (40, 50)).tolist()
    boxes = read_boxes(folder / "a_001.txt")  # left: x - ceil(0.6) in 1-based pixels
    np.testing.assert_allclose(boxes[0], first - [1, 0, 0, 0])
    assert len(list(folder.glob("a_*.json"))) == 12


def test_reset_runs_record_their_starts_and_failures(tmp_path, seqs):
    config = {"name": "fast", "drift": 4.0}  # 4 px a frame on a 6 px wide target that moves 1 px
    run_one_pass(config, seqs[:1], tmp_path / "out", make_tracker=Counter(), progress=False, experiment="reset")
    meta = json.loads((tmp_path / "out" / "fast" / "reset" / "a.json").read_text())
    # drifting 3 px a frame from the target: no overlap on the 2nd frame after a start (3 px: 3 of 6
    # wide still overlap; 6 px: none); a start on frame 1, restarts 5 frames after each failure
    assert meta["resets"] == {"rule": "vot2016", "starts": [1, 8, 15, 22], "failures": [3, 10, 17, 24]}
    boxes = read_boxes(tmp_path / "out" / "fast" / "reset" / "a.txt")
    assert np.isnan(boxes[3:7]).all() and np.isfinite(boxes[7]).all()


def eval_reset(seqs_root, out, *extra) -> int:
    return cli.main(["eval", "kcf", "--dataset", "otb", "--root", str(seqs_root), "--out", str(out), "--experiment",
                     "reset", "--no-progress", *extra])


def test_the_reset_rule_is_part_of_a_run_and_of_its_report(tmp_path, capsys, caplog):
    """A run's failures are its rule's: the rule is recorded in its sidecar and its key, a run of
    one rule is never read as the other's, and the report scores each with its own."""
    root, out = tmp_path / "data", tmp_path / "out"
    write_otb(root, "seqA", seed=0, n_frames=N)
    sidecar = out / "kcf" / "reset" / "seqA.json"
    assert eval_reset(root, out) == 0
    assert "(reset-based, VOT2016 MATLAB toolkit, trax 2016 region overlap)" in capsys.readouterr().out
    first = json.loads(sidecar.read_text())
    assert first["resets"]["rule"] == "vot2016"
    assert eval_reset(root, out, "--protocol", "vot-toolkit") == 0
    second = json.loads(sidecar.read_text())
    assert second["resets"]["rule"] == "vot-toolkit" and second["run_key"] != first["run_key"]
    assert "1 run, 0 already done" in capsys.readouterr().out
    report = ["report", str(out), "--dataset", "otb", "--root", str(root), "--experiment", "reset"]
    assert cli.main(report + ["--report-dir", str(tmp_path / "r")]) == 0
    assert "overlaps and failures: vot-toolkit (vot-toolkit 0.9" in capsys.readouterr().out
    assert json.loads((tmp_path / "r" / "reset.json").read_text())["rule"]["name"] == "vot-toolkit"
    assert cli.main(report + ["--protocol", "vot2016"]) != 0
    assert ("--protocol vot2016: these reset-based runs were made with the vot-toolkit rule"
            in capsys.readouterr().err)
    del second["resets"]["rule"]  # as dcfkit 0.9.0 wrote it: its failures a continuous overlap's
    sidecar.write_text(json.dumps(second))
    assert cli.main(report) != 0
    assert "left out, its failures were decided by dcfkit <= 0.9.0's continuous overlap" in caplog.text
    assert eval_reset(root, out, "--protocol", "vot-toolkit") == 0  # recomputed, never reused
    assert "1 run, 0 already done" in capsys.readouterr().out
    assert "whose failures another rule decided (dcfkit <= 0.9.0's continuous overlap)" in caplog.text


@pytest.mark.parametrize("experiment, protocol, said", [
    ("reset", "otb", "--protocol otb scores one-pass runs; --experiment reset takes vot2016 or vot-toolkit"),
    ("ope", "vot2016", "--protocol vot2016 is a rule of the reset experiment; give --experiment reset"),
])
def test_a_protocol_of_another_experiment_is_an_error(tmp_path, capsys, experiment, protocol, said):
    for command in ("eval", "report"):
        args = ["kcf", "--out", str(tmp_path / "out")] if command == "eval" else [str(tmp_path / "out")]
        assert cli.main([command, *args, "--dataset", "otb", "--root", str(tmp_path), "--experiment", experiment,
                         "--protocol", protocol]) != 0
        assert said in capsys.readouterr().err


def test_eval_and_report_of_each_experiment(tmp_path, capsys):
    """Every table and file names its experiment; TRE and SRE get their page, LaTeX the reset table."""
    root = tmp_path / "data"
    for i, name in enumerate(("seqA", "seqB")):
        write_otb(root, name, seed=i, n_frames=N)
    out, report_dir = tmp_path / "out", tmp_path / "report"
    for experiment in ("tre", "sre", "reset"):
        assert cli.main(["eval", "kcf", "--dataset", "otb", "--root", str(root), "--out", str(out),
                         "--experiment", experiment, "--no-progress"]) == 0
        said = capsys.readouterr().out
        assert f"-> {out / 'kcf' / experiment}" in said
        report = ["report", str(out), "--dataset", "otb", "--root", str(root), "--experiment", experiment,
                  "--report-dir", str(report_dir / experiment)]
        assert cli.main(report) == 0
        printed = capsys.readouterr().out
        named = f"experiment {experiment.upper()} ("
        folder = report_dir / experiment
        assert printed.startswith(named)
        if experiment == "reset":
            scores = json.loads((folder / "reset.json").read_text())
            assert scores["overall"][0]["tracker"] == "kcf" and scores["overall"][0]["sequences"] == 2
            assert "EAO over sequence lengths" in printed and scores["interval"] == [N, N]
            assert scores["experiment"]["name"] == "reset" and scores["max_frames"] is None
            texts = ["reset_overall.txt", "reset_per_sequence.md", "statistics.txt", "statistics.md"]
            assert (folder / "reset_overall.csv").read_text().splitlines()[1].endswith(",reset")
            assert (folder / "statistics.csv").read_text().splitlines()[0].endswith(",rule,experiment")
            assert cli.main(report + ["--format", "latex"]) == 0
            latex = capsys.readouterr().out
            assert latex == (folder / "reset_overall.tex").read_text()
            assert r"\caption{Experiment RESET (" in latex and "EAO [CI]" in latex and r"kcf & " in latex
        else:
            record = json.loads((folder / "report.json").read_text())
            assert record["settings"]["experiment"] == experiment and record["overall"][0]["sequences"] == 2
            assert record["experiment"]["name"] == experiment and record["settings"]["max_frames"] is None
            assert f"{named}" in printed and "each sequence's runs pooled" in printed
            assert (folder / "success.png").is_file()
            texts = ["overall.txt", "overall.md", "per_sequence.txt", "statistics.txt", "statistics.md"]
            assert (folder / "overall.csv").read_text().splitlines()[0].endswith(",protocol,experiment")
            assert (folder / "statistics.csv").read_text().splitlines()[1].endswith(f",otb,{experiment}")
            assert rf"\caption{{Experiment {experiment.upper()} (" in (folder / "overall.tex").read_text()
            assert cli.main(report + ["--html"]) == 0  # dcfkit < 0.10 refused --html but for one pass
            page = (folder / "report.html").read_text()
            assert f"dcfkit report ({experiment.upper()}): 1 tracker on otb" in page
        for name in texts:
            assert (folder / name).read_text().startswith(named), name
    assert cli.main(["report", str(out), "--dataset", "otb", "--root", str(root), "--experiment", "reset",
                     "--html"]) != 0
    assert "--html: reset-based runs have no report page" in capsys.readouterr().err


def test_an_ablation_runs_and_pools_an_experiment(tmp_path, capsys):
    root = tmp_path / "data"
    write_otb(root, "seqA", seed=0, n_frames=N)
    spec = write_spec(tmp_path / "spec.yaml", """
name: tre
dataset: {name: otb, root: data}
experiment: tre
variants:
  kcf: {config: kcf}
  dsst: {config: dsst}
""")
    assert load_spec(spec).experiment == "tre"
    assert cli.main(["ablate", str(spec), "--out", str(tmp_path / "out"), "--jobs", "1", "--no-progress"]) == 0
    printed = capsys.readouterr().out
    runs = len(tre_starts(load_dataset("otb", root)[0].ground_truth))
    assert f"2 jobs ({2 * runs} distinct runs)" in printed
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["experiment"] == "tre" and all(r["failed"] == 0 for r in summary["overall"])
    latex = (tmp_path / "out" / "summary.tex").read_text()  # the variants compared, as a paper's table
    assert latex.startswith("\\begin{table*}") and r"\caption{Ablation tre. Experiment TRE (" in latex
    assert "Variant & Mean [CI] & $\\Delta$ [CI] & $p$ & W/T/L" in latex and "difference from kcf" in latex
    assert len(list((tmp_path / "out").glob(f"*/tre/seqA_{runs:03d}.json"))) == 2
    assert (tmp_path / "out" / "kcf" / "tre" / f"seqA_{runs:03d}.json").is_file()  # OUT/<variant>/tre/, as eval's
    bad = write_spec(tmp_path / "bad.yaml", "name: x\ndataset: otb\nexperiment: reset\nvariants: {k: kcf}\n")
    with pytest.raises(ConfigError, match=r"bad.yaml: experiment: expected one of ope, tre, sre, got 'reset' "
                                          r"\(reset runs: dcfkit eval --experiment reset"):
        load_spec(bad)


@pytest.mark.slow
def test_an_experiment_killed_with_sigkill_resumes_where_it_stopped(tmp_path):
    root = tmp_path / "data"
    write_otb(root, "seqA", seed=0, n_frames=60)
    out = tmp_path / "out"
    cmd = [sys.executable, "-m", "dcfkit.cli", "eval", "strcf", "--dataset", "otb", "--root", str(root),
           "--out", str(out), "--experiment", "tre", "--no-progress"]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    try:
        deadline = time.monotonic() + 120
        while len(list(out.glob("strcf/tre/*.json"))) < 3 and proc.poll() is None and time.monotonic() < deadline:
            time.sleep(0.01)
        proc.send_signal(signal.SIGKILL)
    finally:
        proc.kill()
        output = proc.communicate()[0].decode(errors="replace")
    assert proc.returncode == -signal.SIGKILL, output
    before = {p: p.read_bytes() for p in out.glob("strcf/tre/*.json")}
    assert 3 <= len(before) < 20, f"{len(before)} of 20 runs finished when killed: cannot test resume"
    rerun = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    assert rerun.returncode == 0, rerun.stdout + rerun.stderr
    assert f"{20 - len(before)} run, {len(before)} already done, 0 failed" in rerun.stdout
    assert all(path.read_bytes() == content for path, content in before.items())
    assert len(list(out.glob("strcf/tre/*.json"))) == 20 and not list(out.rglob("*.tmp"))


def test_tre_and_reset_runs_start_at_the_first_valid_box(tmp_path, seqs):
    gt = seqs[0].ground_truth.copy()
    gt[:2] = np.nan  # frames 1-2 without ground truth: one pass and SRE cannot start, TRE and reset can
    seq = Sequence("late", seqs[0].frames, gt, {}, "fake")
    for experiment in ("ope", "sre"):
        with pytest.raises(DatasetError, match="NaN or empty"):
            run_one_pass(CONFIG, [seq], tmp_path / "out", make_tracker=Counter(), progress=False, experiment=experiment)
    tre = run_one_pass(CONFIG, [seq], tmp_path / "out", make_tracker=Counter(), progress=False, experiment="tre")
    assert tre["done"] and not tre["failed"]
    first = json.loads((tmp_path / "out" / "drift" / "tre" / "late_001.json").read_text())
    assert first["init_box"] == gt[2].tolist() and first["frames"] == N - 2
    run_one_pass(CONFIG, [seq], tmp_path / "out", make_tracker=Counter(), progress=False, experiment="reset")
    assert json.loads((tmp_path / "out" / "drift" / "reset" / "late.json").read_text())["resets"]["starts"][0] == 3


def test_the_one_pass_run_is_tres_first_and_is_tracked_once(tmp_path, seqs):
    """OPE's run of a sequence and TRE's runs from frame 1's box (the first; a short sequence
    repeats it) are one run: made by either experiment, it is copied into the other under its
    name, not tracked again; the boxes are those of TRE run into an empty folder."""
    made, out = Counter(), tmp_path / "out"
    run_one_pass(CONFIG, seqs, out, make_tracker=made, progress=False)
    assert made.made == 2
    tre = run_one_pass(CONFIG, seqs, out, make_tracker=made, progress=False, experiment="tre")
    starts = tre_starts(seqs[0].ground_truth)
    assert starts[:2] == [0, 0]  # 25 frames: splitSeqTRE repeats starts
    assert made.made == 2 + 2 * (len(starts) - starts.count(0)) and len(tre["done"]) == 2 * len(starts)
    alone = tmp_path / "alone"
    run_one_pass(CONFIG, seqs, alone, make_tracker=Counter(), progress=False, experiment="tre")
    for name in (f"{s.name}_{k:03d}" for s in seqs for k in range(1, len(starts) + 1)):
        for end in (".txt", ".confidence"):
            assert (out / "drift" / "tre" / f"{name}{end}").read_bytes() == \
                (alone / "drift" / "tre" / f"{name}{end}").read_bytes(), name + end
    copied = json.loads((out / "drift" / "tre" / "a_001.json").read_text())
    one_pass = json.loads((out / "drift" / "a.json").read_text())
    assert copied == {**one_pass, "sequence": "a_001"}
    tracked = made.made
    again = run_one_pass(CONFIG, seqs, out, make_tracker=made, progress=False, experiment="tre")
    assert again["done"] == [] and made.made == tracked  # the copies are runs done
    # the other way round: TRE first, then OPE copies its first run
    run_one_pass(CONFIG, seqs, alone, make_tracker=made, progress=False)
    assert made.made == tracked
    assert (alone / "drift" / "b.txt").read_bytes() == (alone / "drift" / "tre" / "b_001.txt").read_bytes()


def test_a_run_of_another_config_or_from_another_box_is_not_taken_for_tres_first(tmp_path, seqs):
    """TRE's first run is tracked when OPE's was made by another config, or when frame 1's box,
    from which OPE starts, is one TRE cannot start from (OTB's splitSeqTRE wants x, y > 0)."""
    out, starts = tmp_path / "out", tre_starts(seqs[0].ground_truth)
    run_one_pass(CONFIG, seqs, out, make_tracker=Counter(), progress=False)
    made = Counter()
    run_one_pass({**CONFIG, "drift": 2.0, "name": "drift"}, seqs, out, make_tracker=made, progress=False,
                 experiment="tre")
    assert made.made == 2 * len(starts)
    gt = seqs[0].ground_truth.copy()
    gt[0] = [-3.0, 3, 6, 7]  # partly left of the image: a one-pass start, not a TRE start
    seq = Sequence("left", seqs[0].frames, gt, {}, "fake")
    run_one_pass(CONFIG, [seq], out, make_tracker=Counter(), progress=False)
    made = Counter()
    run_one_pass(CONFIG, [seq], out, make_tracker=made, progress=False, experiment="tre")
    assert made.made == len(tre_starts(gt))
    assert json.loads((out / "drift" / "tre" / "left_001.json").read_text())["init_box"] == gt[1].tolist()


@pytest.mark.parametrize("meanwhile", ["removed", "unreadable"])
def test_a_twin_another_command_changes_before_the_copy_is_tracked(tmp_path, seqs, monkeypatch, meanwhile):
    """OPE's folder is not TRE's to claim: when its run of ``a`` is removed, or cannot be read,
    between the plan finding it done and the copy, TRE tracks that run itself, and every TRE
    run ends done, with its files."""
    from dcfkit.running.plan import RunPlan

    out, starts = tmp_path / "out", tre_starts(seqs[0].ground_truth)
    run_one_pass(CONFIG, seqs, out, make_tracker=Counter(), progress=False)
    found = RunPlan.made_elsewhere

    def then_changed(self, p):
        twins = found(self, p)
        if meanwhile == "removed":
            for path in (out / "drift").glob("a.*"):
                path.unlink()
        else:
            (out / "drift" / "a.txt").unlink()
            (out / "drift" / "a.txt").mkdir()  # reading it fails: not a file
        return twins

    monkeypatch.setattr(RunPlan, "made_elsewhere", then_changed)
    made = Counter()
    tre = run_one_pass(CONFIG, seqs, out, make_tracker=made, progress=False, experiment="tre")
    assert made.made == 2 * len(starts) - starts.count(0)  # b's first run copied; a's tracked
    assert len(tre["done"]) == 2 * len(starts) and not tre["failed"]
    record = json.loads((out / "drift" / "tre" / "a_001.json").read_text())
    assert record["sequence"] == "a_001" and (out / "drift" / "tre" / "a_001.txt").is_file()
