"""``dcfkit track`` (one target through a video or a folder of frames) and ``dcfkit demo``
(a generated sequence, no data needed)."""
from __future__ import annotations

import argparse
import itertools
import sys
from pathlib import Path
from typing import Iterator

import numpy as np

from dcfkit.analysis.metrics import score_sequence
from dcfkit.cli.common import MAX_DEMO_FRAMES, frame_count, parse_box, seed
from dcfkit.cli.selection import check_display, select_box
from dcfkit.config.overrides import parse_overrides
from dcfkit.datasets.synthetic import make_sequence
from dcfkit.datasets.video import READ_TIMEOUT, FrameSource, open_source
from dcfkit.datasets.video_writer import DEFAULT_FPS, VideoWriter, check_output_file
from dcfkit.errors import InputError, clip
from dcfkit.store.files import StoreError, format_boxes, format_confidence, format_times
from dcfkit.store.results import CONFIDENCE_END, TIME_END
from dcfkit.experiments.loop import Step, steps, track
from dcfkit.signals import INTERRUPTS, termination_deferred
from dcfkit.tracker.tracker import load_tracker

TRACK_NOTES = f"""--video reads a file, a camera (0 is the first), a stream URL or a named pipe one frame at a
time, and each box is printed (or written to --out) as soon as its frame is tracked: Ctrl-C or
SIGTERM ends a run on an endless source and keeps every box. A camera that stops giving frames
ends the run with an error, and so does a stream that gives none for {READ_TIMEOUT:g} s; a stream that ends
is said on stderr. The Motion JPEG damage check (docs/hardening.md) reads a file's frames
twice, so it applies to files only. --select opens a matplotlib window: it needs a display and
tkinter (on Debian or Ubuntu: apt install python3-tk) or another window backend."""


def add_track_arguments(p: argparse.ArgumentParser) -> None:
    p.epilog = TRACK_NOTES
    p.add_argument("config", help="config file or shipped name (strcf, bacf, dr2track, kcf, dsst)")
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--video", help="video file, camera number (0: the first camera), stream URL (rtsp://, "
                     "http://, udp://... as OpenCV's FFmpeg opens it) or named pipe")
    src.add_argument("--frames", help="folder of image files, tracked in natural name order (frame2 before frame10)")
    first = p.add_mutually_exclusive_group(required=True)
    first.add_argument("--box", help="initial box x,y,w,h (0-based pixels unless --one-based); "
                       "write --box=-5,10,40,30 when x is negative")
    first.add_argument("--select", action="store_true", help="draw the initial box on the first frame in a window "
                       "(needs a display; the box drawn is printed on stderr)")
    p.add_argument("--one-based", action="store_true", help="--box and --out use 1-based (OTB toolkit) pixels")
    p.add_argument("--out", help="write one x,y,w,h line per frame here, and beside it OUT.confidence (peak,apce,score "
                   "per frame) and OUT.time (seconds per frame) (default: x,y,w,h,peak,apce,score lines on stdout); each "
                   "line is written as its frame is tracked")
    p.add_argument("--save-video", help="write an annotated video (.mp4, .avi, .mkv, .mov or .m4v) at the source's "
                   f"frame rate ({DEFAULT_FPS:g} fps for a folder of frames or a video that declares none)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar (shown on stderr when it is a "
                   "terminal)")
    p.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a config key, e.g. label.mu=0.3")


def run_track(args: argparse.Namespace) -> int:
    """Track, printing or writing each frame's box as soon as it is tracked; whatever ends the
    run (an error, the end of a live source, Ctrl-C, or SIGTERM and SIGHUP, which
    :func:`dcfkit.cli.main` turns into an interrupt), the boxes of the frames done are kept."""
    tracker = load_tracker(args.config, overrides=parse_overrides(args.set))
    offset = 1.0 if args.one_based else 0.0
    init_box = None if args.select else _shifted(parse_box(args.box), -offset)
    if args.out == "":
        raise InputError("--out: an empty file name (leave --out out to print the boxes)")
    lines = BoxLines(check_output_file(args.out, "--out") if args.out is not None else None, offset)
    writer = VideoWriter(args.save_video, DEFAULT_FPS) if args.save_video else None
    if args.select:
        check_display()  # before a camera or stream is opened
    source = open_source(args.video, args.frames)
    if writer:
        _keep_rate(writer, source, args.video)
    frames = source.frames
    if args.select:
        init_box, frames = _selected(frames, offset)
    from tqdm.auto import tqdm  # lazy: tqdm.auto probes for Jupyter on import

    progress = tqdm(total=source.total, unit="frame", desc=tracker.name, dynamic_ncols=True,
                    disable=True if args.no_progress else None)  # None: on a terminal only
    lines.bar = progress
    try:
        for step in steps(tracker, frames, init_box):
            lines.add(step)
            if writer:
                writer.write(step.image, {tracker.name: step.box}, f"frame {step.index + 1}")
            progress.update()
    finally:  # an error on frame k keeps the boxes of frames 1..k-1
        progress.close()
        if writer:
            writer.close()
        lines.close(tracker.name)
    if source.live and source.total is None:
        print(f"--video: {source.name}: the stream ended after frame {lines.count}", file=sys.stderr)
    return 0


def _selected(frames: Iterator[np.ndarray], offset: float) -> tuple[tuple[float, ...], Iterator[np.ndarray]]:
    """``--select``: the 0-based box drawn on the first frame, said on stderr as ``--box``
    would give it, and the frames to track, that frame first."""
    frames = iter(frames)
    first = next(frames)
    box = select_box(first)
    print(f"--select: --box {','.join('%g' % v for v in _shifted(box, offset))}", file=sys.stderr)
    return box, itertools.chain([first], frames)


def _shifted(box: tuple[float, ...], offset: float) -> tuple[float, ...]:
    x, y, w, h = box
    return x + offset, y + offset, w, h


def _keep_rate(writer: VideoWriter, source: FrameSource, video: str | None) -> None:
    """``--save-video`` at the rate ``source`` declares; else the default, said for a video."""
    if source.fps:
        writer.fps = source.fps
    elif video is not None:
        print(f"--save-video: {source.name} declares no frame rate; the video is written at {writer.fps:g} fps",
              file=sys.stderr)


def beside(out: Path, ending: str) -> Path:
    """``boxes.txt`` -> ``boxes.txt.confidence``: a file written with ``--out``, named after the
    whole name, so that two ``--out`` names never share one."""
    return out.with_name(out.name + ending)


def check_out(path: Path, companion: bool) -> None:
    """Refuse an ``--out`` file that would fail or block at its open after the other files of
    the run were emptied: a dangling link; for a ``companion``, written beside the boxes
    unasked, anything but a regular file (the boxes may go to a FIFO or /dev/stdout)."""
    if path.is_symlink() and not path.exists():
        raise InputError(f"--out: {clip(str(path))} is a link to nothing")
    if companion and path.exists() and not path.is_file():
        raise InputError(f"--out: {clip(str(path))} is not a regular file")


class BoxLines:
    """Each frame's box as soon as it is tracked. With ``--out``: the boxes (x,y,w,h, as the
    toolkits read them), the confidence (peak,apce,score) and the seconds of each frame, a line a
    frame in three files, opened at the first box (a run that fails before it leaves the files
    of an earlier run) and flushed at each line, so that a run that is killed keeps every frame
    it tracked. Else one x,y,w,h,peak,apce,score line a frame on stdout, flushed (frame 1 and
    held blank frames: nan,nan,nan, they have no response)."""

    def __init__(self, out: Path | None, offset: float):
        self.out, self.offset = out, offset
        self.paths = [out, beside(out, CONFIDENCE_END), beside(out, TIME_END)] if out else []
        for i, path in enumerate(self.paths):
            check_output_file(path, "--out")
            check_out(path, companion=i > 0)
        self.files, self.count, self.seconds, self.bar = [], 0, 0.0, None

    def add(self, step: Step) -> None:
        box = format_boxes(step.box[None], self.offset)
        confidence = format_confidence(np.array(step.confidence))
        if self.out is None:
            self._print(box[:-1] + "," + confidence)
        else:
            self._write((box, confidence, format_times([step.seconds])))
        self.count, self.seconds = self.count + 1, self.seconds + step.seconds

    def _print(self, line: str) -> None:
        if self.bar is not None and not self.bar.disable and sys.stdout.isatty() and sys.stderr.isatty():
            self.bar.write(line, file=sys.stdout, end="")  # the bar is cleared and redrawn under the line
        else:
            sys.stdout.write(line)
        sys.stdout.flush()

    def _write(self, lines: tuple[str, str, str]) -> None:
        with termination_deferred(INTERRUPTS):  # the three files end at the same frame
            for i, (path, line) in enumerate(zip(self.paths, lines)):
                try:
                    if len(self.files) == i:
                        self.files.append(open(path, "w", encoding="utf-8", buffering=1))
                    self.files[i].write(line)  # line-buffered: one write() of a whole line
                except OSError as exc:
                    raise StoreError(f"--out: cannot write {clip(str(path))}: {exc.strerror or exc}") from None

    def close(self, name: str) -> None:
        """Close the files and say how many frames were tracked (nothing if none were)."""
        for path, file in zip(self.paths, self.files):
            try:
                file.close()
            except OSError as exc:  # the last buffered line, on a full disk
                raise StoreError(f"--out: cannot write {clip(str(path))}: {exc.strerror or exc}") from None
        if self.count:
            where = f"; boxes in {self.out}" if self.out else ""
            print(f"{name}: {self.count} frames, {self.count / max(self.seconds, 1e-9):.1f} fps{where}",
                  file=sys.stderr)


def add_demo_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--trackers", default="strcf,dr2track", help="comma-separated configs")
    p.add_argument("--frames", type=frame_count, default=120, help=f"sequence length (2 to {MAX_DEMO_FRAMES})")
    p.add_argument("--seed", type=seed, default=0, help="random seed of the generated sequence (a whole number >= 0)")
    p.add_argument("--save-video", default="dcfkit_demo.mp4", help="annotated video ('' to skip)")


def run_demo(args: argparse.Namespace) -> int:
    """Each tracker on one generated sequence: scores, fps and an annotated video."""
    writer = VideoWriter(args.save_video) if args.save_video else None  # fail before tracking
    seq = make_sequence(n_frames=args.frames, seed=args.seed)
    results = {}
    for name in args.trackers.split(","):
        tracker = load_tracker(name)
        distractors = []
        run = track(tracker, seq.frames, seq.ground_truth[0],
                    lambda i, image, box, t: distractors.append(t.last_distractors))
        fps = (len(seq.frames) - 1) / max(float(run.times[1:].sum()), 1e-9)
        results[tracker.name] = (run.boxes, score_sequence(run.boxes, seq.ground_truth), fps, distractors)
    print(f"synthetic sequence: {len(seq.frames)} frames, a look-alike distractor passes the target")
    print(f"{'tracker':<12} {'precision@20':>12} {'AUC':>6} {'fps':>7}")
    for name, (_, scores, fps, _) in results.items():
        print(f"{name:<12} {scores['precision']:>12.3f} {scores['auc']:>6.3f} {fps:>7.1f}")
    if writer:
        for i, image in enumerate(seq.frames):
            boxes = {"ground truth": seq.ground_truth[i], **{name: r[0][i] for name, r in results.items()}}
            writer.write(image, boxes, f"frame {i + 1}", points={name: r[3][i] for name, r in results.items()})
        writer.close()
        print(f"annotated video: {args.save_video} (circles: the distractors each tracker repressed)")
    return 0
