"""report.html (dcfkit.analysis.report_html): what the page's data holds, checked against independent
computations, and the page itself in a real headless Chromium (skipped where there is none):
it loads without console errors or requests, its overall table sorts, its plots are drawn,
its tooltips and legends work and its thumbnails decode.
"""
from __future__ import annotations

import base64
import hashlib
import json
import math
import os
import re
import shutil
from pathlib import Path

import cv2
import numpy as np
import pytest
from test_ablation import write_otb

from dcfkit import cli
from dcfkit.ablation import load_spec, sensitivity
from dcfkit.ablation.page import config_changes, sensitivity_charts
from dcfkit.analysis.metrics import iou
from dcfkit.analysis.report_html import render
from dcfkit.analysis.report_html.provenance import folder_provenance
from dcfkit.analysis.report_html.thumbnails import choose_frames, crop_window
from dcfkit.config import load_config
from dcfkit.datasets import load_dataset
from dcfkit.store import platforms as dcfkit_platforms

HOSTILE = "<img src=x onerror=alert(1)>&amp;</script>"  # user text that must stay text
HOSTILE_NAME = "<img src=x onerror=alert(1)><script>alert(2)"  # as a tracker (a folder name: no slash)
URL = re.compile(r"(?i)(?:[a-z][a-z0-9+.-]*:)?//")  # any absolute or protocol-relative URL


def page_data(html: str) -> dict:
    block = re.search(r'<script type="application/json" id="report-data">(.*?)</script>', html, re.S)
    return json.loads(block.group(1))


# --------------------------------------------------------------------------- the page's data


def test_user_text_stays_text_and_the_page_holds_no_url():
    page = {"title": f"report {HOSTILE}", "protocol": "protocol otb: x", "subtitle": "see https://example.org/",
            "trackers": [HOSTILE], "sections": [{"kind": "table", "id": "overall", "title": "Overall",
                                                  "columns": [], "rows": [[HOSTILE, "//cdn.example/x.js", 0.5]]}]}
    html = render(page)
    assert html.count("<script") == 2 and html.count("</script>") == 2  # the data block and the page's script
    assert "<img" not in html and "example.org" in html and not URL.search(html)
    assert page_data(html) == page  # JSON escapes only: the data reads back unchanged
    # the Content-Security-Policy names the page's own script by its hash, and nothing else runs
    script = re.search(r"<script>(.*?)</script>", html, re.S).group(1)
    digest = base64.b64encode(hashlib.sha256(script.encode()).digest()).decode()
    assert f"script-src 'sha256-{digest}'" in html and "default-src 'none'" in html


def test_the_thumbnails_overlaps_match_hand_computed_iou():
    gt = np.array([[0, 0, 10, 10]] * 4, float)
    boxes = np.array([[5, 0, 10, 10], [0, 0, 10, 10], [20, 20, 5, 5], [np.nan] * 4])
    assert iou(boxes, gt) == pytest.approx([50 / 150, 1, 0, 0])


def test_frames_are_the_first_and_the_worst_of_each_third():
    n = 31  # frames 1..30 split into thirds [1, 11), [11, 21), [21, 31)
    gt = np.tile([10.0, 10, 20, 20], (n, 1))
    good = gt.copy()
    bad = gt.copy()
    bad[5] += [15, 0, 0, 0]      # IoU 5/35 at frame index 5
    bad[7] += [5, 0, 0, 0]       # IoU 15/25: not the worst of the first third
    bad[25] = np.nan             # lost: IoU 0, the worst of the last third
    gt[15] = np.nan              # out of view: never chosen
    bad[15] += [19, 0, 0, 0]
    bad[18] += [2, 0, 0, 0]
    assert choose_frames(gt, [good, bad]) == [0, 5, 18, 25]


def test_the_crop_holds_every_box_in_the_frames_aspect():
    boxes = np.array([[600, 300, 20, 30], [900, 500, 25, 25], [np.nan] * 4])
    x, y, w, h = crop_window(boxes, (720, 1280))
    assert w / h == pytest.approx(1280 / 720) and 0 <= x and 0 <= y and x + w <= 1280 and y + h <= 720
    assert x <= 600 and y <= 300 and x + w >= 925 and y + h >= 525
    x, y, w, h = crop_window(boxes[:1], (720, 1280))  # one small target: a 320 px wide view around it
    assert w == pytest.approx(320) and x <= 600 and x + w >= 620


def test_config_changes_name_each_changed_key():
    base = load_config("dr2track")
    assert config_changes(base, load_config("dr2track", {"label.mu": 0.5, "name": "x"})) == ["label.mu: 0.25 → 0.5"]
    changed = config_changes(base, load_config("ablations/dr2track_no_ma"))
    assert changed == ["search.name: motion_aware → fixed"]  # motion-aware's own parameters are not listed
    assert config_changes(base, base) == []


PRODUCT_SPEC = """
dataset: otb
variants:
  KCF: kcf
grid:
  base: KCF
  mode: product
  parameters:
    solver.sigma: {label: s, values: [0.3, 0.5]}
    solver.lam: {label: l, values: [0.0001, 0.001]}
"""


def test_sensitivity_in_product_mode_is_the_mean_and_range_over_the_other_parameter(tmp_path):
    (tmp_path / "spec.yaml").write_text(PRODUCT_SPEC, encoding="utf-8")
    spec = load_spec(tmp_path / "spec.yaml")
    auc = {"KCF": 0.0, "s=0.3, l=0.0001": 0.1, "s=0.3, l=0.001": 0.3, "s=0.5, l=0.0001": 0.6, "s=0.5, l=0.001": 0.7}
    overall = [{"variant": v.name, "auc": auc[v.name], "precision": None, "sequences": 2} for v in spec.variants]
    sigma, lam = sensitivity(spec, overall)
    assert sigma["x"] == [0.3, 0.5] and sigma["names"] == ["0.3", "0.5"] and sigma["band"]
    mean, low, high = sigma["metrics"]["auc"]
    assert mean == pytest.approx([0.2, 0.65]) and low == pytest.approx([0.1, 0.6]) and high == pytest.approx([0.3, 0.7])
    assert lam["metrics"]["auc"][0] == pytest.approx([0.35, 0.5])
    assert all(math.isnan(v) for v in lam["metrics"]["precision"][0])  # no precision: nothing to average
    assert (sigma["base_x"], lam["base_x"]) == (0.5, 0.0001)  # KCF's σ and λ


SWEEP_OFF_BASE_SPEC = """
dataset: otb
variants:
  KCF: kcf
grid:
  base: KCF
  parameters:
    solver.sigma: {label: s, values: [0.1, 0.2]}
"""


def test_the_sensitivity_chart_spans_a_base_value_outside_the_swept_ones(tmp_path):
    """KCF's σ is 0.5, the sweep 0.1 and 0.2: the dotted base line must fall inside the chart."""
    (tmp_path / "spec.yaml").write_text(SWEEP_OFF_BASE_SPEC, encoding="utf-8")
    spec = load_spec(tmp_path / "spec.yaml")
    overall = [{"variant": v.name, "auc": 0.5, "precision": 0.6, "sequences": 2} for v in spec.variants]
    chart, = sensitivity_charts(spec, overall)["charts"]
    low, high = chart["xlim"]
    assert chart["vline"]["x"] == 0.5 and low < 0.1 and 0.5 < high


def test_provenance_of_old_and_new_sidecars(tmp_path):
    folder = tmp_path / "t"
    folder.mkdir()
    (folder / "a.json").write_text(json.dumps({"frames": 3, "run_key": "k1", "dcfkit_version": "0.4.0"}))
    (folder / "b.json").write_text(json.dumps({
        "frames": 3, "run_key": "k1", "dcfkit_version": "0.4.0", "command": ["dcfkit", "eval", "my config.yaml"],
        "cwd": "/w", "machine": {"host": "h", "cpu": "C", "cores": 8, "system": "Linux", "python": "3.11"},
        "time": "2026-01-02T00:00:00+00:00", "config": {"name": "t"}}))
    prov = folder_provenance(folder, ["a", "b", "c"], base=tmp_path / "t_report")
    assert prov["sequences"] == 2 and prov["run_keys"] == [["k1", 2]]
    # older sidecars recorded the working directory and the host: read, and not shown on a shared page
    assert sorted(prov["commands"]) == [["dcfkit eval 'my config.yaml'", 1], ["not recorded", 1]]
    assert ["C, 8 cores, Linux, Python 3.11", 1] in prov["machines"]
    assert prov["platforms"] == [["not recorded", 2]]  # sidecars older than 0.6.0 hold none
    assert prov["folder"] == "../t"  # relative to the page's folder
    assert folder_provenance(tmp_path, ["a"], base=tmp_path) == {"folder": ".", "sequences": 0}


# --------------------------------------------------------------------------- in Chromium

CHROMIUM_ARGS = ["--no-sandbox", "--disable-gpu", "--disable-background-networking", "--disable-component-update",
                 "--disable-sync", "--no-first-run", "--disable-quic"]


@pytest.fixture(scope="module")
def browser():
    """Playwright driving the system's Chromium (Debian's `chromium`), never a downloaded one."""
    sync_api = pytest.importorskip("playwright.sync_api", reason="playwright is not installed (pip install playwright)")
    executable = shutil.which("chromium") or shutil.which("chromium-browser")
    if executable is None:
        pytest.skip("no Chromium on PATH (Debian: apt-get install chromium); the browser tests need one")
    with sync_api.sync_playwright() as playwright:
        chromium = playwright.chromium.launch(executable_path=executable, args=CHROMIUM_ARGS)
        yield chromium
        chromium.close()


def open_page(browser, path: Path):
    """(page, problems): ``problems`` collects console errors and warnings, uncaught errors,
    dialogs and any request but the page's own file."""
    page = browser.new_page(viewport={"width": 1280, "height": 900})
    problems: list[str] = []
    page.on("console", lambda m: problems.append(f"console {m.type}: {m.text}") if m.type in ("error", "warning")
            else None)
    page.on("pageerror", lambda e: problems.append(f"page error: {e}"))
    page.on("dialog", lambda d: (problems.append(f"dialog: {d.message}"), d.dismiss()))
    page.on("request", lambda r: problems.append(f"request: {r.url}") if r.url != path.as_uri() else None)
    page.goto(path.as_uri())
    return page, problems


def column(page, table: str, index: int) -> list[str]:
    return page.locator(f"{table} tbody tr td:nth-child({index})").all_inner_texts()


def check_sorting(page, table: str, rows: list[dict], name: str) -> None:
    """Clicking a header sorts the rows by it (their values read from ``rows``, the data the
    page was written from), descending first for numbers, and a second click ascending."""
    for key, label in (("fps", "fps"), ("auc", "AUC")):
        value = {r[name]: r[key] for r in rows}
        button = page.locator(f"{table} thead th button", has_text=re.compile(f"^{label}$"))
        button.click()
        shown = column(page, table, 1)
        assert sorted(shown) == sorted(value)
        assert [value[n] for n in shown] == sorted(value.values(), reverse=True), f"{label} descending"
        button.click()
        assert [value[n] for n in column(page, table, 1)] == sorted(value.values()), f"{label} ascending"


def check_plots(page, expected_charts: int, selector: str = "svg.chart") -> None:
    charts = page.locator(selector)
    assert charts.count() == expected_charts
    for i in range(expected_charts):
        box = charts.nth(i).locator("path.line").first.bounding_box()
        assert box is not None and box["width"] > 50, f"chart {i} has no drawn curve"


def check_thumbnails(page, sequences) -> None:
    """Every thumbnail is a JPEG that decodes, 160 px wide; frame 1's ground truth is drawn."""
    page.locator("#frames").scroll_into_view_if_needed()
    sizes = page.evaluate("""async () => Promise.all([...document.querySelectorAll('svg.thumb image')].map(
        async (node) => { const im = new Image(); im.src = node.getAttribute('href'); await im.decode();
                          return [im.naturalWidth, im.naturalHeight]; }))""")
    assert len(sizes) >= 2 * len(sequences) and all(w == 160 and h > 0 for w, h in sizes)
    assert page.locator(".card").count() == len(sequences)
    assert page.locator(".card").first.locator("rect.gt").count() >= 1


def check_tooltip_and_legend(page, curves: dict, thresholds: list, trackers: list[str]) -> None:
    """The tooltip gives each curve's value at the pointer; a legend click hides a tracker."""
    chart = page.locator("#plots svg.chart").first  # the success plot
    overlay = chart.locator("rect.overlay")
    box = overlay.bounding_box()
    i = 10  # threshold 0.5 of 21
    overlay.hover(position={"x": box["width"] * i / (len(thresholds) - 1), "y": box["height"] / 2})
    tip = page.locator(".tip")
    assert tip.is_visible() and "Overlap threshold: 0.50" in tip.inner_text()
    rows = [row.locator("span").all_inner_texts() for row in tip.locator(".tip-row").all()]
    assert {label: value for _, label, value in rows} == {t: f"{curves[t]['success'][i]:.3f}" for t in trackers}
    first = page.locator("#plots .legend .lg.l-t0").first
    curve = page.locator("#plots svg.chart").first.locator("g.s-t0 path.line")
    assert curve.is_visible()
    first.click()
    assert not curve.is_visible() and page.locator(".card .sc.s-t0").first.is_hidden()
    first.click()
    assert curve.is_visible()


def check_filter(page, table: str, sequence: str) -> None:
    page.locator(f"section:has({table}) input[type=search]").fill(sequence)
    shown = [t for t, visible in zip(column(page, table, 2), page.locator(f"{table} tbody tr").evaluate_all(
        "rows => rows.map(r => !r.hidden)")) if visible]
    assert shown and set(shown) == {sequence}


def run_report(tmp_path, root: Path, dataset: str, sequences: list[str], configs: list) -> Path:
    """`dcfkit eval` of ``configs`` (name, overrides) then `dcfkit report --html`; the page's path."""
    out = tmp_path / "out"
    for config, overrides in configs:
        args = [config, "--dataset", dataset, "--root", str(root), "--sequences", ",".join(sequences),
                "--out", str(out), "--no-progress"] + [f"--set={k}={v}" for k, v in overrides.items()]
        assert cli.main(["eval", *args]) == 0
    assert cli.main(["report", str(out), "--dataset", dataset, "--root", str(root),
                     "--sequences", ",".join(sequences), "--html"]) == 0
    return out.parent / "out_report" / "report.html"


def check_statistics(page, statistics: dict, trackers: list[str]) -> None:
    """Each tracker's row: its AUC with the interval report.json holds, a bar per interval, and
    the baseline's own difference empty; the method is named under the table."""
    rows = page.locator("#statistics-table tbody tr")
    assert rows.count() == len(trackers)
    for i, tracker in enumerate(trackers):
        auc = statistics["means"][tracker]["auc"]
        text = rows.nth(i).inner_text()
        shown = [float(v) for v in re.search(r"(\d\.\d{3}) \[(\d\.\d{3}), (\d\.\d{3})\]", text).groups()]
        # JavaScript's toFixed and Python's format may round a last 5 apart
        assert shown == pytest.approx([auc["mean"], auc["ci_low"], auc["ci_high"]], abs=0.0011), text
    assert page.locator("#statistics-table svg.ci").count() >= 2 * len(trackers)
    assert "BCa bootstrap" in page.locator("#statistics").inner_text()


def check_report(browser, path: Path, sequences) -> None:
    html = path.read_text(encoding="utf-8")
    assert not URL.search(html), URL.search(html)
    evaluation = json.loads((path.parent / "report.json").read_text())
    page, problems = open_page(browser, path)
    assert "protocol otb" in page.locator("header .protocol").inner_text()
    check_sorting(page, "#overall-table", evaluation["overall"], "tracker")
    check_plots(page, 3 + len(evaluation["attribute_curves"]), "#plots svg.chart, #attribute-plots svg.chart")
    long_term = bool(evaluation["long_term"].get("rows"))  # dcfkit eval writes confidences: a precision-recall plot
    assert page.locator("svg.chart").count() == 3 + len(evaluation["attribute_curves"]) + long_term
    if long_term:  # Pr falls from 1: the curve has height even where its Re spans little
        box = page.locator("#long-term svg.chart path.line").first.bounding_box()
        assert box is not None and box["height"] > 50
    trackers = [r["tracker"] for r in evaluation["overall"]]
    check_tooltip_and_legend(page, evaluation["curves"], evaluation["thresholds"]["success"], trackers)
    check_filter(page, "#per-sequence-table", sequences[-1].name)
    check_statistics(page, evaluation["statistics"], trackers)
    check_thumbnails(page, sequences)
    assert page.locator("#provenance").inner_text().count("dcfkit eval") >= len(trackers)
    assert not problems, problems
    page.close()


def test_report_page_of_a_synthetic_run_in_chromium(tmp_path, browser, capsys):
    root = tmp_path / "data"
    for i, name in enumerate(("seqA", "seqB")):
        write_otb(root, name, seed=i)
    # a hostile tracker name: shown as text, runs nothing (a dialog or an error would be caught)
    path = run_report(tmp_path, root, "otb", ["seqA", "seqB"], [("kcf", {}), ("strcf", {"name": f"'{HOSTILE_NAME}'"})])
    check_report(browser, path, load_dataset("otb", root))
    sidecar = json.loads((tmp_path / "out" / "kcf" / "seqA.json").read_text())  # what the provenance reads
    assert sidecar["command"][:3] == ["dcfkit", "eval", "kcf"] and "cwd" not in sidecar
    assert sidecar["machine"]["cores"] == os.cpu_count() and "host" not in sidecar["machine"]
    page, problems = open_page(browser, path)
    assert HOSTILE_NAME in page.locator("#overall-table").inner_text() and not problems
    assert page.locator("#provenance").inner_text().count(dcfkit_platforms.describe(sidecar["platform"])) >= 2


def test_report_page_of_a_real_run_in_chromium(tmp_path, browser, shared_data):
    root = shared_data / "UAV123_10fps"
    names = ["wakeboard7", "wakeboard10"]  # 67 and 157 frames
    path = run_report(tmp_path, root, "uav123_10fps", names, [("kcf", {}), ("strcf", {})])
    check_report(browser, path, load_dataset("uav123_10fps", root, names))


GRID_SPEC = """
name: html
dataset: {name: otb, root: data}
variants:
  KCF: {config: kcf}
  STRCF: {config: strcf}
grid:
  base: KCF
  parameters:
    solver.sigma: {label: σ, values: [0.3, 0.5]}
"""


def test_ablation_page_in_chromium(tmp_path, browser):
    for i, name in enumerate(("seqA", "seqB")):
        write_otb(tmp_path / "data", name, seed=i)
    (tmp_path / "spec.yaml").write_text(GRID_SPEC, encoding="utf-8")
    out = tmp_path / "out"
    assert cli.main(["ablate", str(tmp_path / "spec.yaml"), "--out", str(out), "--jobs", "1", "--no-progress"]) == 0
    path = out / "report.html"
    assert not URL.search(path.read_text(encoding="utf-8"))
    summary = json.loads((out / "summary.json").read_text())
    page, problems = open_page(browser, path)
    check_sorting(page, "#variants-table", summary["overall"], "variant")
    changes = dict(zip(column(page, "#variants-table", 1), column(page, "#variants-table", 2)))
    assert changes["σ=0.3"] == "solver.sigma: 0.5 → 0.3" and changes["σ=0.5"] == "(same as the base)"
    assert "solver.name: kernel_ridge → admm_strcf" in changes["STRCF"]
    sensitivity = page.locator("#sensitivity svg.chart")
    assert sensitivity.count() == 1 and sensitivity.locator("circle").count() == 4  # 2 values x precision, AUC
    assert sensitivity.locator("line.vline").count() == 1  # the base, σ=0.5
    check_plots(page, 3 + 1 + 0)  # the OTB plots and the sensitivity plot; no attributes in OTB-layout data
    check_statistics(page, summary["statistics"], list(summary["statistics"]["means"]))
    check_thumbnails(page, ["seqA", "seqB"])
    assert not problems, problems
