"""Size of report.html and the time to write it (and, with --browser, to open it in Chromium)
for T trackers x S sequences of fake results on 1280x720 frames.

    python benchmarks/report_html.py                  # 3 trackers x 8 sequences, then 10 x 123
    python benchmarks/report_html.py --trackers 10 --sequences 123 --frames 300 --browser

The results are made up (the ground truth plus a drift that grows at a random frame) and
stored as `dcfkit eval` stores them, sidecars included; the sequences carry UAV123's twelve
attributes at random, so the page has every section of a UAV123 report. Prints the page's
bytes, the seconds to write the page alone (thumbnails included) and the whole report
(scores, tables, matplotlib plots, page), and with --browser the milliseconds from opening the
file to its load event in headless Chromium.
"""
import argparse
import shutil
import tempfile
import time
from pathlib import Path

import cv2
import numpy as np

from dcfkit.analysis.report import score_folders, write_files
from dcfkit.analysis.report_html import report_page, write_page
from dcfkit.config import load_config
from dcfkit.datasets import ATTRIBUTE_NAMES, Sequence
from dcfkit.datasets.synthetic import make_sequence
from dcfkit.store.provenance import dcfkit_version, invocation, machine, now, run_key
from dcfkit.store.results import ResultStore

CONFIGS = ("kcf", "dsst", "strcf", "bacf", "dr2track", "arcf", "autotrack")


def make_frames(folder: Path, count: int = 6) -> list[Path]:
    """``count`` distinct 1280x720 JPEGs (every sequence cycles through them)."""
    seq = make_sequence(n_frames=count, size=(720, 1280), target=(40, 60), seed=0)
    paths = []
    for k, frame in enumerate(seq.frames):
        paths.append(folder / f"{k:02d}.jpg")
        cv2.imwrite(str(paths[-1]), frame, [cv2.IMWRITE_JPEG_QUALITY, 90])
    return paths


def make_sequences(images: list[Path], count: int, frames: int, rng) -> list[Sequence]:
    t = np.arange(frames)[:, None]
    out = []
    for i in range(count):
        start = rng.uniform([100, 100], [1000, 500])
        path = start + np.hstack([40 * np.sin(t / 25 + i), 3 * t * rng.uniform(-1, 1)]) % [1100, 580]
        gt = np.hstack([path, np.tile(rng.uniform(20, 90, 2), (frames, 1))])
        attributes = {a: bool(rng.random() < 0.4) for a in ATTRIBUTE_NAMES}
        out.append(Sequence(f"seq{i:03d}", tuple(images[k % len(images)] for k in range(frames)), gt, attributes,
                            "synthetic"))
    return out


def write_results(out: Path, trackers: int, sequences: list[Sequence], rng) -> None:
    """Made-up boxes for each tracker, stored as dcfkit eval stores them."""
    for j in range(trackers):
        config = {**load_config(CONFIGS[j % len(CONFIGS)]), "name": f"tracker{j}"}
        key = run_key(config)
        store = ResultStore(out / config["name"])
        store.folder.mkdir(parents=True)
        for seq in sequences:
            n = len(seq)
            fail = rng.integers(1, n) if rng.random() < 0.5 else n
            drift = np.cumsum(rng.normal(0, 1.5, (n, 2)), axis=0) + (np.arange(n) >= fail)[:, None] * 8.0 * (
                np.arange(n)[:, None] - fail)
            boxes = seq.ground_truth.copy()
            boxes[:, :2] += drift
            boxes[0] = seq.ground_truth[0]
            times = rng.uniform(0.005, 0.02, n)
            meta = {"sequence": seq.name, "dataset": seq.dataset, "tracker": config["name"],
                    "init_box": [float(v) for v in seq.init_box], "fps": float(n / times.sum()),
                    "total_time": float(times.sum()), "run_key": key, "dcfkit_version": dcfkit_version(),
                    "plugins": [], "time": now(), **invocation(), "machine": machine(), "config": config,
                    "times": times.tolist()}
            store.write(seq, boxes, meta, times)


def open_in_chromium(page: Path) -> float:
    """Milliseconds from opening ``page`` to its load event in headless Chromium."""
    from playwright.sync_api import sync_playwright  # optional: only --browser needs it

    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=shutil.which("chromium"),
                                             args=["--no-sandbox", "--disable-gpu", "--no-first-run"])
        tab = browser.new_page(viewport={"width": 1280, "height": 900})
        tab.goto(page.as_uri())
        load = tab.evaluate("performance.getEntriesByType('navigation')[0].loadEventEnd")
        browser.close()
    return load


def measure(trackers: int, count: int, frames: int, browser: bool, seed: int = 0) -> None:
    rng = np.random.default_rng(seed)
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        (tmp / "frames").mkdir()
        sequences = make_sequences(make_frames(tmp / "frames"), count, frames, rng)
        write_results(tmp / "out", trackers, sequences, rng)
        report_dir = tmp / "out_report"
        start = time.perf_counter()
        folders, results, evaluation = score_folders(tmp / "out", sequences, None, report_dir)
        write_files(evaluation, report_dir)
        files = time.perf_counter() - start
        start = time.perf_counter()
        path = write_page(report_page(evaluation, sequences, results, folders), report_dir / "report.html")
        page = time.perf_counter() - start
        line = (f"{trackers} trackers x {count} sequences x {frames} frames: report.html {path.stat().st_size:,} "
                f"bytes, page written in {page:.2f} s (whole report {files + page:.2f} s)")
        if browser:
            line += f", opened in Chromium in {open_in_chromium(path):.0f} ms"
        print(line, flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--trackers", type=int, default=None, help="default: 3, then 10")
    parser.add_argument("--sequences", type=int, default=None, help="default: 8, then 123")
    parser.add_argument("--frames", type=int, default=150, help="frames per sequence (default 150)")
    parser.add_argument("--browser", action="store_true", help="also time opening the page in headless Chromium")
    args = parser.parse_args()
    cases = [(args.trackers, args.sequences)] if args.trackers or args.sequences else [(3, 8), (10, 123)]
    for trackers, count in cases:
        measure(trackers or 3, count or 8, args.frames, args.browser)


if __name__ == "__main__":
    main()
