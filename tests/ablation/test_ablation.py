"""Ablation specs (expansion, validation), resumable runs (SIGKILL), local vs Dask, failures.

Datasets are tiny synthetic sequences written in the OTB layout (1-based annotations).
"""
from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
from pathlib import Path

import cv2
import numpy as np
import pytest

from dcfkit import ablation, cli
from dcfkit.ablation import expand, load_spec, run_ablation
from dcfkit.analysis.statistics import holm
from dcfkit.config import load_config, shipped_config_dir
from dcfkit.datasets import load_dataset, read_boxes
from dcfkit.datasets.synthetic import make_sequence
from dcfkit.errors import ConfigError, DcfkitError
from dcfkit.tracker.tracker import load_tracker

N_FRAMES = 12


def write_otb(root: Path, name: str, seed: int, n_frames: int = N_FRAMES) -> None:
    """One synthetic sequence as ROOT/<name>/img/0001.jpg... + groundtruth_rect.txt (1-based)."""
    seq = make_sequence(n_frames=n_frames, size=(120, 160), target=(16, 20), seed=seed)
    img = root / name / "img"
    img.mkdir(parents=True)
    for k, frame in enumerate(seq.frames):
        cv2.imwrite(str(img / f"{k + 1:04d}.jpg"), frame)
    gt = seq.ground_truth + [1, 1, 0, 0]
    (root / name / "groundtruth_rect.txt").write_text("".join("%g,%g,%g,%g\n" % tuple(b) for b in gt))


@pytest.fixture
def data(tmp_path):
    root = tmp_path / "data"
    for i, name in enumerate(("seqA", "seqB", "seqC", "seqD")):
        write_otb(root, name, seed=i)
    return root


def write_spec(path: Path, text: str) -> Path:
    path.write_text(text, encoding="utf-8")
    return path


GRID_SPEC = """
name: {name}
dataset: {{name: otb, root: data}}
sequences: [seqA, seqB]
variants:
  full: {{config: dr2track}}
  local-strcf: {{config: strcf_copy.yaml, overrides: {{solver.iterations: 3}}}}
grid:
  base: full
  mode: {mode}
  parameters:
    regularizers.temporal.theta: [4, 12]
    label.mu: {{label: mu, values: [0, 0.5]}}
"""


# --------------------------------------------------------------------------- expansion


@pytest.mark.parametrize("mode", ["sweep", "product"])
def test_spec_expands_to_the_job_list(tmp_path, mode):
    (tmp_path / "strcf_copy.yaml").write_text((shipped_config_dir() / "strcf.yaml").read_text())
    spec = load_spec(write_spec(tmp_path / "spec.yaml", GRID_SPEC.format(name="g", mode=mode)))
    jobs = expand(spec)

    theta, mu = "regularizers.temporal.theta", "label.mu"
    if mode == "sweep":  # one at a time, the other parameter at the base (θ=12, μ=0.25)
        points = [("regularizers.temporal.theta=4", {theta: 4}), ("regularizers.temporal.theta=12", {theta: 12}),
                  ("mu=0", {mu: 0}), ("mu=0.5", {mu: 0.5})]
    else:  # full product, first parameter slowest
        points = [(f"regularizers.temporal.theta={t}, mu={m}", {theta: t, mu: m})
                  for t in (4, 12) for m in (0, 0.5)]
    expected = ([("full", load_config("dr2track")),
                 ("local-strcf", load_config(tmp_path / "strcf_copy.yaml", {"solver.iterations": 3}))]
                + [(name, load_config("dr2track", over)) for name, over in points])
    assert [(j.variant, j.sequence) for j in jobs] == [(n, s) for n, _ in expected for s in ("seqA", "seqB")]
    for job in jobs:
        assert job.config == dict(expected)[job.variant]
    # overrides really applied (not only carried along)
    by_variant = {j.variant: j.config for j in jobs}
    assert by_variant["local-strcf"]["solver"]["iterations"] == 3
    assert by_variant[points[0][0]]["regularizers"]["temporal"]["theta"] == 4.0
    # runs are keyed by what changes the boxes: θ=12 is the base dr2track (θ=12, μ=0.25)
    keys = {j.variant: j.key for j in jobs}
    if mode == "sweep":
        assert keys["regularizers.temporal.theta=12"] == keys["full"]
        assert len(set(keys.values())) == 5
    else:
        assert len(set(keys.values())) == 6
    assert expand(load_spec(tmp_path / "spec.yaml")) == jobs  # deterministic


def test_shipped_specs_expand():
    table3 = load_spec("table3", root=".")
    assert [v.name for v in table3.variants] == ["DR²Track", "DR²Track-DR", "DR²Track-MA", "STRCF"]
    configs = {v.name: v.config for v in table3.variants}
    assert configs["DR²Track-DR"] == load_config("ablations/dr2track_no_ma.yaml")
    assert configs["DR²Track-MA"] == load_config("ablations/dr2track_no_dr.yaml")
    assert configs["STRCF"] == load_config("strcf")
    assert load_spec("table3").root == (shipped_config_dir() / "../../shared/data/UAV123_10fps").resolve()

    sens = load_spec("sensitivity")
    jobs = expand(sens, ["boat1"])
    assert [j.variant for j in jobs] == ["DR²Track", "θ=4", "θ=8", "θ=12", "θ=16", "θ=20",
                                         "μ=0", "μ=0.1", "μ=0.25", "μ=0.5", "N=10", "N=30", "N=50"]
    assert len({j.key for j in jobs}) == 10  # θ=12, μ=0.25 and N=30 are DR²Track itself
    assert {j.variant: j.config for j in jobs}["N=50"] == load_config("dr2track", {"label.top_n": 50})


def test_the_family_spec_holds_every_shipped_tracker():
    family = load_spec("family", root=".")
    shipped = sorted(p.stem for p in shipped_config_dir().glob("*.yaml"))
    assert sorted(v.config["name"] for v in family.variants) == shipped
    assert all(v.config == load_config(v.config["name"]) for v in family.variants)


@pytest.mark.parametrize("text, expected", [
    ("dataset: {name: otb}\nvariant: {a: {config: dr2track}}\n", ["'variant'", "did you mean 'variants'"]),
    ("dataset: {name: otb}\nvariants: {a: {overrides: {label.mu: 1}}}\n", ["variants.a.config", "missing"]),
    ("dataset: {name: otb}\nvariants: {a: {config: dr2track, overrides: {label.mux: 1}}}\n",
     ["variants.a overrides (label.mux):", "did you mean 'mu'"]),  # the typo is the spec's, not the config's
    ("dataset: {name: otb}\nvariants: {a: {config: nope.yaml}}\n", ["variants.a", "config 'nope.yaml' not found"]),
    ("dataset: {name: otb}\nvariants: {a: {config: dr2track, overrides: [label.mu]}}\n",
     ["variants.a.overrides", "mapping of dotted keys"]),
    ("dataset: {name: otbb}\nvariants: {a: {config: dr2track}}\n", ["dataset.name", "unknown dataset 'otbb'"]),
    ("variants: {a: {config: dr2track}}\n", ["dataset.name", "missing"]),
    ("dataset: {name: otb}\ngrid: {base: dr2track, mode: grid, parameters: {label.mu: [0]}}\n",
     ["grid.mode", "sweep, product"]),
    ("dataset: {name: otb}\ngrid: {base: dr2track, parameters: {label.mu: 0.1}}\n",
     ["grid.parameters.label.mu", "non-empty list"]),
    ("dataset: {name: otb}\ngrid: {base: dr2track, parameters: {label.mu: [0.1, 0.1]}}\n",
     ["grid.parameters.label.mu", "listed twice"]),
    ("dataset: {name: otb}\ngrid: {base: dr2track, parameters: {label.topn: [10]}}\n",
     ["grid (label.topn=10)", "topn"]),
    ("dataset: {name: otb}\ngrid: {parameters: {label.mu: [0]}}\n", ["grid.base", "missing"]),
    ("dataset: {name: otb}\n", ["nothing to run"]),
    ("dataset: {name: otb}\nvariants: {1: strcf, '1': bacf}\n", ["variants.1", "given twice"]),  # was one
    ("dataset: {name: otb}\nvariants: {true: strcf, 'True': bacf}\n", ["variants.True", "given twice"]),
])
def test_bad_spec_errors_name_the_file_and_key(tmp_path, text, expected):
    path = write_spec(tmp_path / "bad.yaml", text)
    with pytest.raises(ConfigError) as info:
        load_spec(path)
    message = str(info.value)
    assert str(path) in message
    for part in expected:
        assert part in message


def test_an_empty_sequences_option_is_blamed_on_the_option(tmp_path):
    path = write_spec(tmp_path / "spec.yaml", "dataset: {name: otb}\nvariants: {a: strcf}\n")
    with pytest.raises(ConfigError, match=r"^--sequences \(replacing the spec's sequences\): expected a non-empty"):
        load_spec(path, sequences=" , ")  # the message used to name the spec file


def test_configs_are_relative_to_the_spec_never_to_the_working_directory(tmp_path, monkeypatch):
    for folder in ("cwd", "specs"):
        (tmp_path / folder).mkdir()
    (tmp_path / "cwd" / "mine.yaml").write_text("base: strcf\nname: mine\n")
    path = write_spec(tmp_path / "specs" / "s.yaml", "dataset: {name: otb}\nvariants: {a: {config: mine.yaml}}\n")
    monkeypatch.chdir(tmp_path / "cwd")
    with pytest.raises(ConfigError, match=r"config 'mine.yaml' not found \(looked for .*specs/mine.yaml"):
        load_spec(path)
    (tmp_path / "specs" / "mine.yaml").write_text("base: bacf\nname: mine\n")
    assert load_spec(path).variants[0].config["solver"]["name"] == "admm_bacf"
    # a shipped name is the shipped config, whatever file of that name the working directory holds
    (tmp_path / "cwd" / "strcf.yaml").write_text("base: bacf\nname: strcf\n")
    path.write_text("dataset: {name: otb}\nvariants: {a: {config: strcf.yaml}}\n")
    assert load_spec(path).variants[0].config == load_config("strcf")


def test_root_is_relative_to_the_spec_and_overridable(tmp_path, data, monkeypatch):
    spec_dir = tmp_path / "specs"
    spec_dir.mkdir()
    path = write_spec(spec_dir / "s.yaml", "dataset: {name: otb, root: ../data}\nvariants: {a: {config: strcf}}\n")
    monkeypatch.chdir(spec_dir.parent.parent)  # the working directory does not matter
    assert load_spec(path).root == data.resolve()
    assert [s.name for s in load_spec(path).load_sequences()] == ["seqA", "seqB", "seqC", "seqD"]
    monkeypatch.chdir(tmp_path)
    assert load_spec(path, root="elsewhere").root == tmp_path / "elsewhere"
    with pytest.raises(ConfigError, match="--root"):
        load_spec(path, root="elsewhere").load_sequences()
    assert [j.sequence for j in expand(load_spec(path, sequences="seqC,seqA"))] == ["seqC", "seqA"]


def test_cli_runs_and_lists_jobs(tmp_path, data, capsys):
    spec = str(write_spec(tmp_path / "spec.yaml", "dataset: {name: otb, root: data}\n"
                                                  "variants: {s: {config: strcf}}\n"))
    out = str(tmp_path / "out")
    assert cli.main(["ablate", spec, "--out", out, "--sequences", "seqB", "--jobs", "1", "--no-progress"]) == 0
    printed = capsys.readouterr().out
    assert printed.startswith("spec: experiment OPE (one-pass evaluation; Wu et al., TPAMI 2015), protocol otb\n"
                              "protocol otb: OTB / UAV123 MATLAB toolkit")  # the default scoring rules, named
    assert "\n\n| variant | precision | auc | fps | sequences | failed |\n" in printed
    assert "1 jobs (1 distinct runs): 1 run, 0 already done, 0 failed" in printed
    assert all((tmp_path / "out" / f"{kind}.{ext}").is_file() for kind in ("precision", "success")
               for ext in ("png", "svg"))  # named variants: the OTB plots
    # the summary of the same runs under another protocol: nothing reruns, the columns follow it
    assert cli.main(["ablate", spec, "--out", out, "--sequences", "seqB", "--jobs", "1", "--no-progress",
                     "--protocol", "got10k"]) == 0
    printed = capsys.readouterr().out
    assert printed.splitlines()[1].startswith("protocol got10k: ") and "0 run, 1 already done" in printed
    assert "| variant | precision | auc | ao | sr50 | sr75 | fps | sequences | failed |" in printed
    assert json.loads((tmp_path / "out" / "summary.json").read_text())["protocol"]["name"] == "got10k"
    assert cli.main(["ablate", spec, "--out", out, "--sequences", "seqC,seqB", "--dry-run"]) == 0
    key = expand(load_spec(spec))[0].key
    assert capsys.readouterr().out.splitlines() == [f"todo  {key}  s  seqC", f"done  {key}  s  seqB",
                                                    "2 jobs, 2 distinct runs"]


def test_cli_names_the_variants_of_a_failed_run(tmp_path, data, capsys):
    (data / "seqB" / "img" / "0003.jpg").write_bytes(b"not a jpeg")
    spec = str(write_spec(tmp_path / "spec.yaml", "dataset: {name: otb, root: data}\n"
                                                  "variants: {one: strcf, two: {config: strcf}}\n"))
    assert cli.main(["ablate", spec, "--out", str(tmp_path / "out"), "--sequences", "seqB", "--jobs", "1",
                     "--no-progress"]) == 1
    key = expand(load_spec(spec))[0].key
    printed = capsys.readouterr().out.splitlines()
    assert [line.split(": ")[0] for line in printed if line.startswith("FAILED")] == ["FAILED one, two"]  # as it runs
    failed = [line for line in printed if line.startswith("  FAILED")]  # in the summary
    assert len(failed) == 1 and failed[0].startswith(f"  FAILED one, two [{key}] ") and "0003.jpg" in failed[0]


# --------------------------------------------------------------------------- running


def done_sidecars(out: Path) -> dict[Path, tuple]:
    """Sidecars of finished runs -> (inode, mtime_ns, content)."""
    return {p: (p.stat().st_ino, p.stat().st_mtime_ns, p.read_bytes())
            for p in out.glob("*/*.json") if p.parent.name != "configs"}


def children(pid: int) -> list[int]:
    out = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        with_name = stat.read_text(errors="replace")
        fields = with_name[with_name.rfind(")") + 2:].split()
        if int(fields[1]) == pid:
            out.append(int(stat.parent.name))
    return out


def alive(pid: int) -> bool:
    try:
        text = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return text[text.rfind(")") + 2:].split()[0] != "Z"


def product_grid(path: Path, n: int) -> Path:
    """A spec whose grid is an n x n x n product (label.mu, label.top_n, label.exclusion), every point valid."""
    mus, tops, exclusions = [round(0.05 * i, 2) for i in range(n)], list(range(1, n + 1)), [0.5 + i for i in range(n)]
    return write_spec(path, f"dataset: {{name: otb, root: data}}\ngrid:\n  base: dr2track\n  mode: product\n"
                            f"  parameters:\n    label.mu: {mus}\n    label.top_n: {tops}\n    label.exclusion: {exclusions}\n")


RAISE_IT = r"\(dcfkit ablate --max-variants N, \$DCFKIT_MAX_VARIANTS or dcfkit.ablation.spec.MAX_VARIANTS raise it\)"


def test_the_variant_limit_is_named_and_can_be_raised(tmp_path, data, monkeypatch, capsys):
    """An 11x11x11 grid (1331 points) was over the limit of 1,000, which only a program could raise."""
    big = product_grid(tmp_path / "big.yaml", 11)
    with pytest.raises(ConfigError, match=r"big.yaml: grid.parameters: 1331 grid points \(product\) and 0 named "
                                          r"variants; a spec has at most 1000 variants " + RAISE_IT):
        load_spec(big)
    small, out = str(product_grid(tmp_path / "small.yaml", 2)), str(tmp_path / "out")  # 8 variants
    dry_run = ["ablate", small, "--out", out, "--sequences", "seqA", "--dry-run"]
    monkeypatch.setenv("DCFKIT_MAX_VARIANTS", "7")
    assert cli.main(dry_run) == 2 and "a spec has at most 7 variants (dcfkit ablate" in capsys.readouterr().err
    assert len(load_spec(small, max_variants=8).variants) == 8  # the option wins over the variable
    assert cli.main(dry_run + ["--max-variants", "8"]) == 0
    assert capsys.readouterr().out.splitlines()[-1] == "8 jobs, 8 distinct runs"
    monkeypatch.setenv("DCFKIT_MAX_VARIANTS", "8")
    assert len(load_spec(small).variants) == 8
    named = write_spec(tmp_path / "named.yaml", "dataset: otb\nvariants: {a: strcf, b: bacf, c: dr2track}\n")
    with pytest.raises(ConfigError, match=r"named.yaml: variants: 3 variants; a spec has at most 2 " + RAISE_IT):
        load_spec(named, max_variants=2)
    monkeypatch.setenv("DCFKIT_MAX_VARIANTS", "lots")
    with pytest.raises(ConfigError, match=r"\$DCFKIT_MAX_VARIANTS must be a number of variants >= 1, got 'lots'"):
        load_spec(small)
    with pytest.raises(SystemExit):
        cli.main(dry_run + ["--max-variants", "0"])
    assert "argument --max-variants: expected a whole number of variants >= 1, got '0'" in capsys.readouterr().err


@pytest.mark.slow
def test_an_11x11x11_grid_is_read_with_the_limit_raised(tmp_path, data, capsys):
    big = str(product_grid(tmp_path / "big.yaml", 11))
    assert cli.main(["ablate", big, "--out", str(tmp_path / "out"), "--sequences", "seqA", "--max-variants", "1331",
                     "--dry-run"]) == 0
    assert capsys.readouterr().out.splitlines()[-1] == "1331 jobs, 1331 distinct runs"


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="needs Linux /proc to watch the worker processes")
@pytest.mark.slow
def test_sigkill_then_rerun_loses_and_recomputes_nothing(tmp_path, data):
    spec = write_spec(tmp_path / "spec.yaml", """
name: kill
dataset: {name: otb, root: data}
variants:
  dr2: {config: dr2track}
  strcf: {config: strcf}
grid: {base: dr2, parameters: {label.mu: [0, 0.5]}}
""")
    out = tmp_path / "out"
    cmd = [sys.executable, "-m", "dcfkit.cli", "ablate", str(spec), "--out", str(out), "--jobs", "2",
           "--no-progress"]
    total = 4 * 4  # 4 variants x 4 sequences, all different configs
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    try:
        deadline = time.monotonic() + 60
        while not done_sidecars(out) and proc.poll() is None and time.monotonic() < deadline:
            time.sleep(0.01)
        workers = children(proc.pid)
        proc.send_signal(signal.SIGKILL)  # the main process only, as `kill -9 PID`
    finally:
        proc.kill()
        output = proc.communicate()[0].decode(errors="replace")
    assert proc.returncode == -signal.SIGKILL, output
    # the pool's workers die with the main process (no orphan keeps writing)
    deadline = time.monotonic() + 10
    while any(alive(p) for p in workers) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert workers and not any(alive(p) for p in workers)

    before = done_sidecars(out)
    assert 0 < len(before) < total, f"{len(before)} of {total} finished when killed: cannot test resume"
    planted = next(iter(before)).parent / ".seqA.txt.k1ll3d.tmp"  # what a kill mid-write leaves
    planted.write_text("1.000,2.0")

    rerun = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    assert rerun.returncode == 0, rerun.stdout + rerun.stderr
    assert f"{total - len(before)} run, {len(before)} already done, 0 failed" in rerun.stdout
    after = done_sidecars(out)
    assert len(after) == total
    keys = {j.variant: j.key for j in expand(load_spec(spec))}
    for path, state in before.items():  # not rewritten: same file, same time, same content
        assert after[path] == state, path
    assert not list(out.rglob("*.tmp"))  # temporary files of the killed run are gone, never read
    for side in after:
        meta = json.loads(side.read_text())
        boxes = read_boxes(side.with_suffix(".txt"))
        assert meta["frames"] == len(boxes) == N_FRAMES and len(meta["times"]) == N_FRAMES
        assert meta["run_key"] == keys[side.parent.name]  # OUT/<variant>/, the variant's run key
    summary = json.loads((out / "summary.json").read_text())
    assert [r["variant"] for r in summary["overall"]] == ["dr2", "strcf", "label.mu=0", "label.mu=0.5"]
    assert summary["folders"] == {v: v for v in keys}
    assert all(r["failed"] == 0 and 0 <= r["precision"] <= 1 for r in summary["overall"])
    assert summary["protocol"]["name"] == "otb"
    stats = summary["statistics"]  # every variant against the grid's base, Holm across the three
    assert stats["baseline"] == "dr2" and set(stats["differences"]) == {"strcf", "label.mu=0", "label.mu=0.5"}
    ps = [stats["differences"][v]["auc"]["wilcoxon_p"] for v in ("strcf", "label.mu=0", "label.mu=0.5")]
    assert [stats["differences"][v]["auc"]["holm_p"] for v in ("strcf", "label.mu=0", "label.mu=0.5")] == \
        pytest.approx(holm(ps))
    assert (out / "statistics.txt").read_text().splitlines()[1].startswith("statistics over 4 sequences: 95% BCa")
    flat = [line.split(",") for line in (out / "statistics.csv").read_text().splitlines()]
    assert [(r[0], r[1]) for r in flat[1:]] == [(v, s) for v in ("dr2", "strcf", "label.mu=0", "label.mu=0.5")
                                                for s in ("auc", "precision")]
    assert float(flat[3][flat[0].index("d_holm_p")]) == stats["differences"]["strcf"]["auc"]["holm_p"]
    assert (out / "statistics.md").read_text().startswith((out / "statistics.txt").read_text().splitlines()[0])
    assert (out / "summary.md").read_text().splitlines()[4].startswith("| variant | precision | auc | fps |")
    assert (out / "per_sequence.csv").read_text().count("\n") == 1 + total
    assert (out / "per_sequence.csv").read_text().splitlines()[0].endswith(",status,protocol")
    assert (out / "sensitivity_label.mu.png").stat().st_size > 0


def test_job_boxes_match_a_direct_run_and_failures_are_recorded(tmp_path, data):
    broken = data / "seqB" / "img" / "0005.jpg"
    broken.write_bytes(b"not a jpeg")
    spec = load_spec(write_spec(tmp_path / "spec.yaml", """
dataset: {name: otb, root: data}
sequences: [seqA, seqB, seqC]
variants: {s: {config: strcf, overrides: {scale.n_scales: 3}}}
"""))
    out = tmp_path / "out"
    res = run_ablation(spec, out, jobs=1, progress=False)
    key = expand(spec)[0].key
    assert sorted(res["done"]) == [(key, "seqA"), (key, "seqC")]
    assert list(res["failed"]) == [(key, "seqB")]
    assert "0005.jpg" in res["failed"][key, "seqB"] and "not a readable image" in res["failed"][key, "seqB"]
    record = json.loads((out / "s" / "seqB.error").read_text())
    assert record["frame"] == 5 and record["frame_file"] == str(broken.resolve())
    assert not (out / "s" / "seqB.txt").exists()
    rows = {r["sequence"]: r for r in res["summary"]["per_sequence"]}
    assert [rows[s]["status"] for s in ("seqA", "seqB", "seqC")] == ["done", "failed", "done"]
    assert res["summary"]["overall"][0]["failed"] == 1
    # the record of which config made the results is rewritten when damaged (it never was)
    record = out / "configs" / f"{key}.json"
    good = record.read_text()
    record.write_text("garbage")
    run_ablation(spec, out, jobs=1, progress=False)
    assert record.read_text() == good
    assert [j["error"] is not None for j in res["summary"]["jobs"]] == [False, True, False]

    # what a job stored is what the tracker returns when run directly (0-based in memory)
    seq = load_dataset("otb", data, ["seqA"])[0]
    tracker = load_tracker("strcf", overrides={"scale.n_scales": 3})
    tracker.init(seq.frame(0), seq.init_box)
    direct = np.array([seq.init_box] + [tracker.update(seq.frame(i)) for i in range(1, len(seq))])
    stored = read_boxes(out / "s" / "seqA.txt")
    np.testing.assert_allclose(stored, direct, atol=5e-4)

    # a rerun retries the failure only
    again = run_ablation(spec, out, jobs=1, progress=False)
    assert again["done"] == [] and len(again["skipped"]) == 2 and list(again["failed"]) == [(key, "seqB")]


@pytest.mark.slow
def test_local_pool_and_dask_give_identical_boxes(tmp_path, data):
    distributed = pytest.importorskip(
        "distributed", reason="dask.distributed not installed (pip install 'dcfkit[dask]')")
    spec = load_spec(write_spec(tmp_path / "spec.yaml", """
dataset: {name: otb, root: data}
sequences: [seqA, seqD]
variants:
  dr2: {config: dr2track}
  strcf: {config: strcf}
"""))
    local = run_ablation(spec, tmp_path / "local", jobs=2, progress=False)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        dask = run_ablation(spec, tmp_path / "dask", executor="dask", scheduler=cluster.scheduler_address,
                            progress=False)
    assert len(local["done"]) == len(dask["done"]) == 4 and not local["failed"] and not dask["failed"]
    files = sorted(p.relative_to(tmp_path / "local") for pattern in ("*/*.txt", "*/*.confidence")
                   for p in (tmp_path / "local").glob(pattern))  # the boxes and the confidence; timings differ
    assert len(files) == 8
    for rel in files:
        assert (tmp_path / "dask" / rel).read_text() == (tmp_path / "local" / rel).read_text(), rel
    scores = lambda res: [(r["variant"], r["precision"], r["auc"]) for r in res["summary"]["overall"]]  # noqa: E731
    assert scores(local) == scores(dask)


def test_dask_missing_gives_an_install_hint(tmp_path, data, monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)  # import fails as if not installed
    spec = load_spec(write_spec(tmp_path / "spec.yaml", "dataset: {name: otb, root: data}\nsequences: [seqA]\n"
                                                        "variants: {s: {config: strcf}}\n"))
    with pytest.raises(DcfkitError, match=r"pip install 'dcfkit\[dask\]'"):
        run_ablation(spec, tmp_path / "out", executor="dask", progress=False)


def test_a_second_run_on_the_same_folder_is_refused(tmp_path, data):
    fcntl = pytest.importorskip("fcntl", reason="POSIX file locks")
    spec = load_spec(write_spec(tmp_path / "spec.yaml", "dataset: {name: otb, root: data}\nsequences: [seqA]\n"
                                                        "variants: {s: {config: strcf}}\n"))
    out = tmp_path / "out"
    out.mkdir()
    with open(out / ".lock", "a+") as held:  # as a running `dcfkit ablate` holds it
        fcntl.flock(held, fcntl.LOCK_EX | fcntl.LOCK_NB)
        with pytest.raises(DcfkitError, match="another `dcfkit ablate` is writing to"):
            run_ablation(spec, out, jobs=1, progress=False)
    assert not (out / "s").exists()
    (out / "s").write_text("")  # a file where the variant's folder goes: refused before anything runs
    with pytest.raises(DcfkitError, match=r"cannot create the folder .*/s\b"):
        run_ablation(spec, out, jobs=1, progress=False)


def test_a_damaged_run_is_not_scored_and_is_recomputed(tmp_path, data):
    spec = load_spec(write_spec(tmp_path / "spec.yaml", "dataset: {name: otb, root: data}\nsequences: [seqA, seqB]\n"
                                                        "variants: {s: {config: strcf}}\n"))
    out = tmp_path / "out"
    first = run_ablation(spec, out, jobs=1, progress=False)
    key = expand(spec)[0].key
    txt = out / "s" / "seqB.txt"
    good = txt.read_bytes()
    txt.write_bytes(good[:-6])  # truncate -s -6: the last height loses its decimals
    summary = ablation.summarize(spec, out, spec.load_sequences())
    rows = {r["sequence"]: r for r in summary["per_sequence"]}
    assert rows["seqB"]["status"] == "damaged" and summary["overall"][0]["failed"] == 1
    assert summary["overall"][0]["auc"] < first["summary"]["overall"][0]["auc"]  # scored as a failure, not as boxes
    again = run_ablation(spec, out, jobs=1, progress=False)
    assert again["done"] == [(key, "seqB")] and again["skipped"] == [(key, "seqA")]
    assert txt.read_bytes() == good and again["summary"]["overall"][0]["failed"] == 0


def test_eval_and_ablate_key_a_run_alike(tmp_path, data):
    """One run identity: the same resolved config gets the same key from `dcfkit eval` (under
    any name) as from `dcfkit ablate`."""
    from dcfkit.running.evaluation import run_one_pass

    spec = load_spec(write_spec(tmp_path / "spec.yaml", "dataset: {name: otb, root: data}\nsequences: [seqA]\n"
                                                        "variants: {mine: {config: strcf, overrides: {regularizers.temporal.theta: 20}}}\n"))
    (job,) = expand(spec)
    config = {**load_config("strcf", {"regularizers.temporal.theta": 20}), "name": "my-strcf"}
    summary = run_one_pass(config, spec.load_sequences(), tmp_path / "eval", progress=False)
    assert summary["run_key"] == job.key
    assert json.loads((tmp_path / "eval" / "my-strcf" / "seqA.json").read_text())["run_key"] == job.key


@pytest.mark.parametrize("in_the_way", ["s/seqB.json", "precision.png", "configs/{key}.json"])
def test_a_folder_where_an_ablation_file_goes_is_refused_before_tracking(tmp_path, data, in_the_way, monkeypatch):
    spec = load_spec(write_spec(tmp_path / "spec.yaml", "dataset: {name: otb, root: data}\nsequences: [seqA, seqB]\n"
                                                        "variants: {s: {config: strcf}}\n"))
    out = tmp_path / "out"
    (out / in_the_way.format(key=expand(spec)[0].key)).mkdir(parents=True)
    monkeypatch.setattr("dcfkit.experiments.base.track", lambda *a, **k: pytest.fail("tracked before the check"))
    with pytest.raises(DcfkitError, match=r"cannot write the ablation.*: [^ ]+ is a folder; move it away"):
        run_ablation(spec, out, jobs=1, progress=False)


def test_an_unwritable_job_folder_is_refused_before_tracking(tmp_path, data, monkeypatch):
    import tempfile

    spec = load_spec(write_spec(tmp_path / "spec.yaml", "dataset: {name: otb, root: data}\nsequences: [seqA]\n"
                                                        "variants: {s: {config: strcf}}\n"))
    folder = tmp_path / "out" / "s"
    folder.mkdir(parents=True)
    real = tempfile.mkstemp

    def mkstemp(*args, dir=None, **kwargs):  # as a read-only folder refuses a new file (root ignores modes)
        if dir is not None and Path(dir) == folder:
            raise PermissionError(13, "Permission denied")
        return real(*args, dir=dir, **kwargs)

    monkeypatch.setattr(tempfile, "mkstemp", mkstemp)
    monkeypatch.setattr("dcfkit.experiments.base.track", lambda *a, **k: pytest.fail("tracked before the check"))
    with pytest.raises(DcfkitError, match=r"cannot write the ablation's results to .*: Permission denied"):
        run_ablation(spec, tmp_path / "out", jobs=1, progress=False)


def test_a_smoke_ablation_never_replaces_the_full_results(tmp_path, data, capsys):
    spec = str(write_spec(tmp_path / "spec.yaml", "dataset: {name: otb, root: data}\nvariants: {k: {config: kcf}}\n"))
    base = ["ablate", spec, "--out", str(tmp_path / "out"), "--sequences", "seqA", "--jobs", "1", "--no-progress"]
    assert cli.main(base) == 0
    (full,) = (tmp_path / "out").glob("*/seqA.txt")
    before = full.read_bytes()
    capsys.readouterr()
    assert cli.main(base + ["--max-frames", "5"]) != 0
    err = capsys.readouterr().err.strip()
    assert f"holds an intact run of {N_FRAMES} frames and this run of 'seqA' has 5" in err and "\n" not in err
    assert full.read_bytes() == before
