"""``dcfkit track`` (one target through a video or a folder of frames) and ``dcfkit demo``
(a generated sequence, no data needed)."""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..config import parse_overrides
from ..metrics import score_sequence
from ..synthetic import make_sequence
from ..tracker import load_tracker
from ..results import CONFIDENCE_SUFFIX, TIME_SUFFIX, atomic_write, format_boxes, format_confidence, format_times
from ..tracking import Track, empty_track, termination_deferred, track
from ..video import VideoWriter, check_output_file, iter_frames
from .common import MAX_DEMO_FRAMES, frame_count, parse_box, seed


def add_track_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("config", help="config file or shipped name (strcf, bacf, dr2track, kcf, dsst)")
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--video", help="video file")
    src.add_argument("--frames", help="folder of image files, tracked in natural name order (frame2 before frame10)")
    p.add_argument("--box", required=True, help="initial box x,y,w,h (0-based pixels unless --one-based); "
                   "write --box=-5,10,40,30 when x is negative")
    p.add_argument("--one-based", action="store_true", help="--box and --out use 1-based (OTB toolkit) pixels")
    p.add_argument("--out", help="write one x,y,w,h line per frame here, and beside it OUT_confidence (peak,apce "
                   "per frame) and OUT_time (seconds per frame) with OUT's suffix (default: x,y,w,h,peak,apce "
                   "lines on stdout)")
    p.add_argument("--save-video", help="write an annotated video (.mp4, .avi, .mkv, .mov or .m4v)")
    p.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a config key, e.g. label.mu=0.3")


def run_track(args: argparse.Namespace) -> int:
    """Track and write the boxes; whatever ends the run (an error, Ctrl-C, or SIGTERM and
    SIGHUP, which :func:`dcfkit.cli.main` turns into an interrupt), the boxes of the frames
    done are written."""
    tracker = load_tracker(args.config, overrides=parse_overrides(args.set))
    out = check_output_file(args.out, "--out") if args.out else None
    if out:
        for tag in (CONFIDENCE_SUFFIX, TIME_SUFFIX):
            check_output_file(beside(out, tag), "--out")
    offset = 1.0 if args.one_based else 0.0
    x, y, w, h = parse_box(args.box)
    writer = VideoWriter(args.save_video) if args.save_video else None

    def annotate(index, image, box, _tracker):
        writer.write(image, {tracker.name: box}, f"frame {index + 1}")

    done = empty_track()
    try:
        track(tracker, iter_frames(args.video, args.frames), (x - offset, y - offset, w, h),
              annotate if writer else None, partial=done)
    finally:  # an error on frame k keeps the boxes of frames 1..k-1
        if writer:
            writer.close()
        _write_boxes(done, out, offset, tracker.name)
    return 0


def beside(out: Path, tag: str) -> Path:
    """``boxes.txt`` -> ``boxes_confidence.txt``: a file written with ``--out``."""
    return out.with_name(f"{out.stem}{tag}{out.suffix}")


def _write_boxes(done: Track, out: Path | None, offset: float, name: str) -> None:
    """``--out``: the boxes (x,y,w,h, as the toolkits read them), the confidence (peak,apce)
    and the seconds of each frame in three files; stdout: one x,y,w,h,peak,apce line a frame
    (frame 1 and held blank frames: nan,nan, they have no response)."""
    if not len(done.boxes):
        return
    if out:
        with termination_deferred():
            atomic_write(out, format_boxes(done.boxes, offset))
            atomic_write(beside(out, CONFIDENCE_SUFFIX), format_confidence(done.confidence))
            atomic_write(beside(out, TIME_SUFFIX), format_times(done.times))
    else:
        boxes = done.boxes + [offset, offset, 0, 0]
        print("".join("%.3f,%.3f,%.3f,%.3f,%.6g,%.6g\n" % (*b, *c) for b, c in zip(boxes, done.confidence)), end="")
    seconds = float(done.times.sum())
    print(f"{name}: {len(done.boxes)} frames, {len(done.boxes) / max(seconds, 1e-9):.1f} fps", file=sys.stderr)


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
