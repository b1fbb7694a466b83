"""Robustness from restarts: each variant of an ablation spec tracks every sequence from several
starting frames (OTB's temporal robustness evaluation, TRE: Wu et al., CVPR 2013), so a few
sequences give many more chances to lose a target than one pass does.

    python benchmarks/restarts.py configs/ablations/departures.yaml \
        [--variants "DR²Track (authors),DR²Track (dcfkit)"] [--root DIR] [--dataset NAME] \
        [--sequences a,b] [--starts 5] [--jobs 2] [--json restarts.json]

Segment k of a sequence of N frames starts at frame floor(k N / starts) (0-based) from that
frame's ground truth and runs to the end (a start whose ground truth is out of view moves
to the next annotated frame). Each segment is scored under the `otb` protocol. Printed per
variant: mean AUC and precision over all segments, and "lost": segments whose last 10 frames
all have IoU 0 with the ground truth (the target not found again by the end).
``--dataset``/``--root`` replace the spec's dataset (e.g. DTB70 or UAVDT with a UAV123 spec).
"""
import os

for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[var] = "1"

import argparse  # noqa: E402
import concurrent.futures  # noqa: E402
import json  # noqa: E402
import sys  # noqa: E402

import numpy as np  # noqa: E402

import dcfkit  # noqa: E402
from dcfkit.ablation import load_spec  # noqa: E402
from dcfkit.analysis.metrics import iou, score_sequence  # noqa: E402
from dcfkit.datasets import load_dataset  # noqa: E402
from dcfkit.experiments.loop import track  # noqa: E402

LOST_TAIL = 10  # frames at the end of a segment that must all miss for it to count as lost


def segment_starts(gt: np.ndarray, starts: int) -> list[int]:
    """0-based first frames of the segments: floor(k N / starts), moved to the next frame
    with a usable ground truth box; duplicates dropped."""
    usable = np.all(np.isfinite(gt), axis=1) & (gt[:, 2] > 0) & (gt[:, 3] > 0)
    firsts = []
    for k in range(starts):
        i = (k * len(gt)) // starts
        while i < len(gt) - LOST_TAIL and not usable[i]:
            i += 1
        if i < len(gt) - LOST_TAIL and i not in firsts:
            firsts.append(i)
    return firsts


def run_segment(config: dict, seq, first: int) -> dict:
    """Track ``seq`` from frame ``first`` (0-based) to its end; scores of that segment, or
    its ``error`` (a failed segment is reported, and the others still run)."""
    try:
        return _track_segment(config, seq, first)
    except Exception as exc:  # noqa: BLE001 - one failed run must not lose the others'
        return {"sequence": seq.name, "first": first, "error": f"{type(exc).__name__}: {exc}"}


def _track_segment(config: dict, seq, first: int) -> dict:
    gt = seq.ground_truth[first:]
    boxes = track(dcfkit.load_tracker(config), (seq.frame(i) for i in range(first, len(seq))), gt[0]).boxes
    scores = score_sequence(boxes, gt, protocol="otb")
    tail = iou(boxes[-LOST_TAIL:], gt[-LOST_TAIL:])
    lost = bool(np.all(np.nan_to_num(tail, nan=0.0) <= 0.0))
    return {"sequence": seq.name, "first": first, "frames": len(gt), "auc": scores["auc"],
            "precision": scores["precision"], "lost": lost}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("spec", help="ablation spec (its named variants are the configs)")
    parser.add_argument("--variants", help="comma-separated variant names (default: all named variants)")
    parser.add_argument("--root", help="benchmark root (default: the spec's)")
    parser.add_argument("--dataset", help="dataset name with --root (default: the spec's)")
    parser.add_argument("--sequences", help="comma-separated sequence names (default: all)")
    parser.add_argument("--starts", type=int, default=5, help="segments per sequence (default 5)")
    parser.add_argument("--jobs", type=int, default=1, help="worker processes (default 1)")
    parser.add_argument("--json", help="write every segment's scores here")
    args = parser.parse_args(argv)

    if args.dataset and not args.root:
        parser.error("--dataset needs --root")
    own_dataset = not args.dataset
    spec = load_spec(args.spec, root=args.root if own_dataset else None,
                     sequences=args.sequences if own_dataset else None)
    variants = {v.name: v.config for v in spec.variants}
    names = [n.strip() for n in args.variants.split(",")] if args.variants else list(variants)
    unknown = [n for n in names if n not in variants]
    if unknown:
        parser.error(f"--variants: not in {args.spec}: {', '.join(unknown)}")
    seqs = spec.load_sequences() if own_dataset else load_dataset(args.dataset, args.root, args.sequences)

    tasks = [(name, seq, first) for name in names for seq in seqs
             for first in segment_starts(seq.ground_truth, args.starts)]
    with concurrent.futures.ProcessPoolExecutor(args.jobs) as pool:
        futures = [pool.submit(run_segment, variants[name], seq, first) for name, seq, first in tasks]
        results = [dict(variant=name, **f.result()) for (name, _, _), f in zip(tasks, futures)]

    for r in results:
        if "error" in r:
            print(f"FAILED {r['variant']} {r['sequence']} from frame {r['first'] + 1}: {r['error']}")
    width = max(len(n) for n in names)
    print(f"{'variant':<{width}}  segments  lost  precision  AUC   (protocol otb, {args.starts} starts a sequence)")
    for name in names:
        rows = [r for r in results if r["variant"] == name and "error" not in r]
        lost = [f"{r['sequence']}@{r['first'] + 1}" for r in rows if r["lost"]]
        print(f"{name:<{width}}  {len(rows):8d}  {len(lost):4d}  {np.mean([r['precision'] for r in rows]):9.3f}  "
              f"{np.mean([r['auc'] for r in rows]):.3f}  {' '.join(lost)}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(results, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
