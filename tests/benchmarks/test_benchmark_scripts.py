"""Every benchmark script runs end to end on a few synthetic frames, so that a change cannot
break one unseen (stages.py and speed.py had: a renamed tracker function, a grey frame the
tracker now refuses as blank). platform_noise.py has its own test. Nothing about their speed
is asserted: that is what they print."""
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import cv2
import pytest

from dcfkit.datasets.synthetic import make_sequence
from dcfkit.datasets.uav123_layout import uav123_sequence_table

BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"
ROOT = BENCHMARKS.parent


@pytest.fixture
def synthetic_uav123(tmp_path) -> Path:
    """A UAV123@10fps root whose one sequence (wakeboard7's frame range) is synthetic."""
    root = tmp_path / "UAV123_10fps"
    folder, first, last = uav123_sequence_table()["UAV123_10fps"]["wakeboard7"]
    seq = make_sequence(n_frames=last - first + 1, size=(120, 160), target=(16, 20))
    frames = root / "data_seq" / "UAV123_10fps" / folder
    frames.mkdir(parents=True)
    for i, image in enumerate(seq.frames):
        cv2.imwrite(str(frames / f"{first + i:06d}.jpg"), image)
    anno = root / "anno" / "UAV123_10fps"
    anno.mkdir(parents=True)
    (anno / "wakeboard7.txt").write_text("".join(f"{x + 1:.2f},{y + 1:.2f},{w:.2f},{h:.2f}\n"
                                                 for x, y, w, h in seq.ground_truth))
    return root


def run(script: str, *args: str, tmp_path: Path) -> str:
    env = {**os.environ, "DCFKIT_TEST_DATA": str(tmp_path / "no data")}
    done = subprocess.run([sys.executable, str(BENCHMARKS / script), *args], env=env, cwd=tmp_path,
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    return done.stdout


@pytest.mark.slow
def test_stages(tmp_path):
    out = run("stages.py", "--synthetic", "--frames", "4", "--json", "stages.json", tmp_path=tmp_path)
    stages = json.loads((tmp_path / "stages.json").read_text())["ms_per_frame"]
    # found through the kinds' contracts, as floor.py finds them: a component's every method
    assert {"patch extraction", "fft", "solver admm_strcf.train", "solver admm_strcf.response", "newton_peak",
            "feature fhog.extract", "label distractor_repressed.make", "scale dsst.update"} <= set(stages)
    assert out.startswith("dr2track on synthetic_720p: ")


@pytest.mark.slow
def test_stages_names_csr_dcfs_mask_and_channel_weights(tmp_path):
    run("stages.py", "--synthetic", "--frames", "4", "--config", "csrdcf", "--json", "stages.json", tmp_path=tmp_path)
    stages = json.loads((tmp_path / "stages.json").read_text())["ms_per_frame"]
    assert any(s.startswith("mask csr_segmentation.") for s in stages), stages
    assert any(s.startswith("channel_weights csr_reliability.") for s in stages), stages


@pytest.mark.slow
def test_floor(tmp_path):
    out = run("floor.py", "--root", str(tmp_path / "none"), "--configs", "kcf,eco_hc", "--frames", "8", "--probe", "3",
              "--repeats", "2", "--json", "floor.json", tmp_path=tmp_path)
    rows = {r["config"]: r for r in json.loads((tmp_path / "floor.json").read_text())["rows"]}
    # the arithmetic of each loop is found: the discrete loop's components and FFTs, and the
    # continuous loop's own numerics (ECO's projection, its Fourier-series peak)
    assert {"extract_stack", "fft", "solver kernel_ridge.train", "subpixel_peak"} <= set(rows["kcf"]["floor_ms"])
    assert {"extract", "project", "newton_maximum", "scale fdsst.update"} <= set(rows["eco_hc"]["floor_ms"])
    for row in rows.values():
        assert row["floor_fps"] == pytest.approx(1000 / sum(row["floor_ms"].values()))
        assert row["ratio"] == pytest.approx(row["fps"] / row["floor_fps"])
    assert "synthetic_720p kcf" in out and "median over the real sequences" in out


@pytest.mark.slow
def test_speed(tmp_path):
    from dcfkit.integrations.opencv import available_opencv_trackers  # reason: only this test asks

    configs = ["kcf"] + (["opencv:CSRT"] if "CSRT" in available_opencv_trackers() else [])  # the yardstick
    out = run("speed.py", "--root", str(tmp_path / "none"), "--configs", ",".join(configs), "--passes", "1",
              "--json", "speed.json", "--synthetic-frames", "4", tmp_path=tmp_path)
    assert "synthetic frames only" in out and "first frame in a fresh process" in out
    assert all(f"synthetic_720p {config}" in out for config in configs), out
    assert (tmp_path / "speed.json").is_file()


@pytest.mark.slow
def test_report_html(tmp_path):
    out = run("report_html.py", "--trackers", "2", "--sequences", "2", "--frames", "5", tmp_path=tmp_path)
    assert out.startswith("2 trackers x 2 sequences x 5 frames: report.html ")


@pytest.mark.slow
def test_same_boxes_saves_then_finds_no_change(tmp_path):
    run("same_boxes.py", "--root", str(tmp_path / "none"), "--configs", "kcf", "--save", "boxes.npz", tmp_path=tmp_path)
    out = run("same_boxes.py", "--root", str(tmp_path / "none"), "--configs", "kcf", "--compare", "boxes.npz",
              tmp_path=tmp_path)
    assert out.rstrip().endswith("1 of 1 runs identical"), out


@pytest.mark.slow
def test_compare_speed_of_a_checkout_with_itself(tmp_path, synthetic_uav123):
    out = run("compare_speed.py", str(ROOT), "--root", str(synthetic_uav123), "--configs", "kcf",
              "--json", "speed.json", tmp_path=tmp_path)
    assert "wakeboard7" in out and "median over sequences" in out
    assert json.loads((tmp_path / "speed.json").read_text())["median"]["kcf"]["ratio"] > 0


@pytest.mark.slow
def test_frame_reading_reads_every_frame_both_ways_and_finds_the_same_pixels(tmp_path, synthetic_uav123):
    out = run("frame_reading.py", str(synthetic_uav123), tmp_path=tmp_path)
    folder, first, last = uav123_sequence_table()["UAV123_10fps"]["wakeboard7"]
    (row,) = [line.split() for line in out.splitlines() if line.startswith(str(synthetic_uav123)[-40:])]
    assert int(row[-5]) == last - first + 1 and row[-1] == "0", out


def test_lockstep_tracks_each_way_and_finds_the_same_results(tmp_path, synthetic_uav123):
    out = run("lockstep.py", str(synthetic_uav123), "--configs", "kcf", "--experiment", "sre", tmp_path=tmp_path)
    (row,) = [line.split() for line in out.splitlines() if line.startswith("kcf ")]
    assert row[1:3] == ["wakeboard7", "12"] and row[-1] == "yes", out


def test_restarts(tmp_path, synthetic_uav123):
    spec = tmp_path / "spec.yaml"
    spec.write_text("name: smoke\ndataset: uav123_10fps\nvariants:\n  plain: kcf\n")
    out = run("restarts.py", str(spec), "--root", str(synthetic_uav123), "--starts", "2", "--json", "restarts.json",
              tmp_path=tmp_path)
    segments = json.loads((tmp_path / "restarts.json").read_text())
    assert [(s["variant"], s["first"], "error" in s) for s in segments] == [("plain", 0, False), ("plain", 33, False)]
    assert "segments  lost  precision  AUC" in out


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("octave") is None, reason="GNU Octave is not installed (apt-get install octave)")
@pytest.mark.skipif(not (ROOT.parent / "shared" / "reference").is_dir(), reason="no ../shared/reference (the authors' code)")
def test_authors_octave(tmp_path, synthetic_uav123):
    done = subprocess.run(["bash", str(BENCHMARKS / "authors_octave.sh"), "strcf", str(synthetic_uav123),
                           str(tmp_path / "out"), "wakeboard7"], capture_output=True, text=True, timeout=1200)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    boxes = (tmp_path / "out" / "UAV123_10fps" / "wakeboard7.txt").read_text().splitlines()
    assert len(boxes) == 67 and all(len(line.split(",")) == 4 for line in boxes)



def _authors_source(variable: str, folder: str) -> Path | None:
    """Where authors_octave.sh finds ECO's or CSR-DCF's checkout ($ECO_CODE / $CSR_CODE, else
    $DCFKIT_REFERENCE/<folder>), or None."""
    reference = Path(os.environ.get("DCFKIT_REFERENCE") or ROOT.parent / "shared" / "reference")
    code = Path(os.environ.get(variable) or reference / folder)
    return code if code.is_dir() and (reference / "DR2Track").is_dir() else None


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("octave") is None, reason="GNU Octave is not installed (apt-get install octave)")
@pytest.mark.parametrize("tracker, variable, folder", [("eco_hc", "ECO_CODE", "ECO"), ("csrdcf", "CSR_CODE", "csr-dcf")])
def test_authors_octave_builds_and_runs_eco_and_csr(tmp_path, synthetic_uav123, tracker, variable, folder):
    """ECO-HC and CSR-DCF: the mex files build (their mtimesx, the segmentation mex against
    OpenCV 4) and a sequence runs to one box per frame, with the fps the run reports."""
    if _authors_source(variable, folder) is None:
        pytest.skip(f"no checkout of the authors' code (${variable}) or no DCFKIT_REFERENCE")
    done = subprocess.run(["bash", str(BENCHMARKS / "authors_octave.sh"), tracker, str(synthetic_uav123),
                           str(tmp_path / "out"), "wakeboard7"], capture_output=True, text=True, timeout=1200)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    boxes = (tmp_path / "out" / "UAV123_10fps" / "wakeboard7.txt").read_text().splitlines()
    assert len(boxes) == 67 and all(len(line.split(",")) == 4 for line in boxes)
    fps = (tmp_path / "out" / "UAV123_10fps" / f"{tracker}_fps.tsv").read_text().splitlines()[1].split("\t")
    assert fps[0] == "wakeboard7" and float(fps[2]) > 0


def test_decide_pairs_each_option_with_its_base(tmp_path, capsys):
    """Hand-made scores: '+ up' wins every sequence by 0.1 (its interval above 0; with 8 sequences
    the exact two-sided Wilcoxon p is 2/256 = 0.0078, Holm x2 = 0.016 < 0.05: adopted); '+ mixed'
    wins 4 and loses 4: the base stands."""
    import csv
    import importlib.util

    spec = importlib.util.spec_from_file_location("decide", ROOT / "benchmarks" / "decide.py")
    decide = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(decide)
    path = tmp_path / "ope" / "per_sequence.csv"
    path.parent.mkdir()
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["variant", "sequence", "precision", "auc", "fps", "frames", "status", "protocol"])
        for i in range(8):
            base = 0.3 + 0.05 * i
            w.writerow(["T", f"s{i}", 0, base, 1, 10, "done", "otb"])
            w.writerow(["T + up", f"s{i}", 0, base + 0.1 + 0.001 * i, 1, 10, "done", "otb"])
            w.writerow(["T + mixed", f"s{i}", 0, base + (0.05 if i % 2 else -0.05), 1, 10, "done", "otb"])
    rows = {r["option"]: r for r in decide.decide(decide.read_scores(path, "auc"))}
    up, mixed = rows["up"], rows["mixed"]
    assert up["difference"].won == 8 and up["difference"].ci_low > 0
    assert up["difference"].wilcoxon_p == pytest.approx(2 / 256) and up["holm"] == pytest.approx(4 / 256)
    assert up["passes"] and not mixed["passes"] and (mixed["difference"].won, mixed["difference"].lost) == (4, 4)
    assert decide.main([str(path)]) == 0
    assert "- T + up: adopt" in capsys.readouterr().out
    # non-inferiority: '+ mixed' (mean 0, lower bound -0.05 by hand: half the sequences lose 0.05)
    # is within a margin of 0.06, not of 0.01; '+ up' is within any
    for margin, kept in ((0.06, True), (0.01, False)):
        rows = {r["option"]: r for r in decide.decide(decide.read_scores(path, "auc"), margin)}
        assert rows["mixed"]["difference"].ci_low >= -0.05 and rows["mixed"]["passes"] is kept and rows["up"]["passes"]
    assert decide.main([str(path), "--margin", "0.06"]) == 0
    assert "- T + mixed: adopt (non-inferiority, δ 0.06)" in capsys.readouterr().out


def test_search_cost_counts_each_run_once_and_splits_by_choice(tmp_path):
    """A hand-built search folder: config A (two trials, two studies) tracked 3 + 2 frames, its
    TRE run from frame 1 a copy of the one-pass run; config B 4 frames; a folder no trial names."""
    out = tmp_path / "search"

    def record(study, n, key, params):
        path = out / "trials" / study / f"{n:04d}.json"
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps({"number": n, "key": key, "params": params}))

    def times(path, values):
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text("".join(f"{v:.8f}\n" for v in values))

    record("fold1", 0, "aaaa", {"scale": "dsst", "mu": 0.5, "iterations": 4})
    record("all", 0, "aaaa", {"scale": "dsst", "mu": 0.5, "iterations": 4})
    record("fold1", 1, "bbbb", {"scale": "pyramid", "mu": 0.25, "iterations": 2, "redetect": "grid"})
    times(out / "runs" / "aaaa" / "s1.time", [0.5, 0.25, 0.25])
    times(out / "runs" / "aaaa" / "tre" / "s1_001.time", [0.5, 0.25, 0.25])  # the copy
    times(out / "runs" / "aaaa" / "tre" / "s1_002.time", [0.5, 0.5])
    times(out / "runs" / "bbbb" / "s1.time", [1.0, 1.0, 1.0, 1.0])
    times(out / "runs" / "cccc" / "s1.time", [9.0])
    printed = run("search_cost.py", str(out), tmp_path=tmp_path)
    # A: 5 frames in 2 s; B: 4 frames in 4 s; together 9 frames in 6 s
    assert "2 configs' runs: 9 frames tracked in 0.00 core-hours of tracking, 1.5 fps" in printed
    assert "left out: 1 folder(s) under runs/ that no trial record names (cccc)" in printed
    rows = {tuple(line.strip("| ").split(" | ")[:2]): line.strip("| ").split(" | ")[2:]
            for line in printed.splitlines() if line.startswith("| ") and not line.startswith("| dimension")}
    assert rows[("scale", "pyramid")] == ["1", "4", "0.00", "67%", "1.0"]
    assert rows[("scale", "dsst")] == ["1", "5", "0.00", "33%", "2.5"]
    assert rows[("iterations", "4")][:2] == ["1", "5"]
    assert rows[("redetect", "(inactive)")][:2] == ["1", "5"] and rows[("redetect", "grid")][:2] == ["1", "4"]
    assert not any(name == "mu" for name, _ in rows)  # real numbers are not split


def test_search_cost_refuses_a_folder_that_is_not_a_search(tmp_path):
    done = subprocess.run([sys.executable, str(BENCHMARKS / "search_cost.py"), str(tmp_path)],
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 2 and "not a search's --out (no trials/ and runs/ in it)" in done.stderr


@pytest.mark.parametrize("where, text, said", [
    ("trials/fold1/0000.json", "{not json", "fold1/0000.json: not a trial record"),
    ("runs/aaaa/s1.time", "0.5\nabc\n", "aaaa/s1.time: not a run's per-frame times (one number a line)")])
def test_search_cost_names_the_file_it_cannot_read(tmp_path, where, text, said):
    out = tmp_path / "search"
    for path, content in (("trials/fold1/0000.json", json.dumps({"key": "aaaa", "params": {}})),
                          ("runs/aaaa/s1.time", "0.5\n"), (where, text)):
        (out / path).parent.mkdir(parents=True, exist_ok=True)
        (out / path).write_text(content)
    done = subprocess.run([sys.executable, str(BENCHMARKS / "search_cost.py"), str(out)],
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 1 and said in done.stderr and "Traceback" not in done.stderr
