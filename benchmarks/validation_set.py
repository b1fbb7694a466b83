"""Build the validation set from fetched snapshots of public repositories (one command).

    python benchmarks/validation_set.py MIRROR OUT [--manifest M] [--reserved R]

MIRROR holds one snapshot per repository as ``MIRROR/OWNER+NAME/repo`` (a bare git directory or
a folder holding ``.git``: what `git clone --mirror` or the library's ``fetch`` leaves). The
set is the fifteen sequences of ``../shared/data/validation/sequences.json`` (``--manifest``),
each checked against its frame count and annotation SHA-256, and the other public sequences
that file's README lists (:data:`EXTRA`), each checked against its frame count and the SHA-256
dcfkit recorded when it first built it. No sequence of ``RESERVED.tsv`` (``--reserved``) is
ever written.

Writes ``OUT/<DATASET>/<sequence>/img/000001.jpg ...`` and ``groundtruth_rect.txt`` (1-based
``x,y,w,h``, ``nan`` where the target is absent): the OTB layout, so ``--dataset otb --root
OUT/<DATASET>`` reads one benchmark and ``--root OUT/all`` (links to every sequence) the whole
set. Needs git. docs/results.md ("The validation set") says what it covers.
"""
from __future__ import annotations

import argparse
import csv
import hashlib
import json
import os
import re
import subprocess
import sys
from pathlib import Path

SHARED = Path(__file__).resolve().parents[2] / "shared" / "data"

#: The public sequences the validation README lists beyond its manifest, as dcfkit converts
#: them: ``format`` "xywh1" (1-based x,y,w,h), "xywh0" (0-based, VOT) or "polygon0" (VOT's four
#: corners, 0-based; their bounding box). ``sha256`` is that of the converted annotation.
EXTRA = [
    {"dataset": "DTB70", "name": "Yacht2", "repo": "FreeZhang96/EMCF", "img_dir": "seq/Yacht2",
     "gt": "seq/anno/Yacht2.txt", "frames": 239, "format": "xywh1",
     "sha256": "0ee8b4acfc380533b662976c58d7e802461f70f1d62e98078778dc65c066cb39"},
    {"dataset": "OTB", "name": "Bird2", "repo": "lifeng9472/IBCCF", "img_dir": "sequences/Bird2/img",
     "gt": "sequences/Bird2/groundtruth_rect.txt", "frames": 99, "format": "xywh1",
     "sha256": "0fb57926f9e0d373c48ac99bc919299134f3cc13776abc39599898d6ffaed079"},
    {"dataset": "OTB", "name": "DragonBaby", "repo": "hyeonseobnam/py-MDNet", "img_dir": "datasets/OTB/DragonBaby/img",
     "gt": "datasets/OTB/DragonBaby/groundtruth_rect.txt", "frames": 113, "format": "xywh1",
     "sha256": "f4402d9c0752467fcc5aec36561143b9cfd54023d50e5769b6dca2160b3b8db1"},
    {"dataset": "VOT", "name": "bag", "repo": "foolwood/DaSiamRPN", "img_dir": "code/bag",
     "gt": "code/bag/groundtruth.txt", "frames": 196, "format": "polygon0",
     "sha256": "3ae95bfc0539c37fda831f74e374dc7fc68455cbf9d4d121bb8a0c16e7abfd14"},
    {"dataset": "VOT-LT", "name": "yamaha", "repo": "Daikenan/LTMU", "img_dir": "demo_sequences/yamaha/color",
     "gt": "demo_sequences/yamaha/groundtruth.txt", "frames": 3143, "format": "xywh0",
     "sha256": "2ca015cc3d355d92e7b64059259a996314c8064d19b93432ff98279f24a2f14a"},
]

IMAGE_ENDINGS = (".jpg", ".jpeg", ".png", ".bmp")


def git(gitdir: Path, *args: str) -> bytes:
    done = subprocess.run(["git", "--git-dir", str(gitdir), *args], capture_output=True)
    if done.returncode:
        raise RuntimeError(f"git {' '.join(args)} in {gitdir}: {done.stderr.decode().strip()}")
    return done.stdout


def snapshot(mirror: Path, repo: str) -> Path:
    """The git directory of ``repo``'s snapshot under ``mirror``."""
    base = mirror / repo.replace("/", "+") / "repo"
    for candidate in (base / ".git", base):
        if candidate.is_dir():
            return candidate
    raise SystemExit(f"{repo}: no snapshot under {base}; fetch it first")


def newest_commit_with(gitdir: Path, path: str) -> str:
    for commit in git(gitdir, "rev-list", "--all", "--date-order").decode().split():
        if git(gitdir, "ls-tree", commit, "--", path).strip():
            return commit
    raise RuntimeError(f"{path} is in no commit of {gitdir}")


def image_blobs(gitdir: Path, commit: str, folder: str) -> list[tuple[int, str, str]]:
    """``(frame number, file name, blob)`` of the images in ``folder``, by frame number."""
    found = []
    for line in git(gitdir, "ls-tree", f"{commit}:{folder}").decode().splitlines():
        meta, name = line.split("\t", 1)
        _, kind, blob = meta.split()
        if kind == "blob" and name.lower().endswith(IMAGE_ENDINGS):
            found.append((int(re.findall(r"\d+", os.path.splitext(name)[0])[-1]), name, blob))
    return sorted(found)


def rows_of(text: str) -> list[list[str]]:
    """The annotation's rows, split on commas, tabs or spaces; trailing blank rows dropped."""
    rows = [r.strip() for r in text.splitlines()]
    while rows and not rows[-1]:
        rows.pop()
    return [[v for v in re.split(r"[,\s]+", r) if v] for r in rows]


def converted(rows: list[list[str]], form: str) -> list[str]:
    """Rows as 1-based ``x,y,w,h`` text (``form`` as in :data:`EXTRA`; manifest rows as written)."""
    if form == "as_written":
        return [",".join(r) for r in rows]
    out = []
    for r in rows:
        v = [float(x) for x in r]
        if any(x != x for x in v):  # NaN: the target is absent
            out.append("nan,nan,nan,nan")
            continue
        if form == "polygon0":
            xs, ys = v[0::2], v[1::2]
            v = [min(xs), min(ys), max(xs) - min(xs), max(ys) - min(ys)]
        shift = 1.0 if form in ("xywh0", "polygon0") else 0.0
        out.append(",".join(f"{x:.6g}" for x in (v[0] + shift, v[1] + shift, v[2], v[3])))
    return out


def build(entry: dict, mirror: Path, out: Path, form: str, sha: str) -> tuple[int, str]:
    """Write one sequence; returns (frames, the annotation's SHA-256), checked against ``sha``."""
    gitdir = snapshot(mirror, entry["repo"])
    images = image_blobs(gitdir, entry.get("commit") or newest_commit_with(gitdir, entry["img_dir"]), entry["img_dir"])
    first, last = entry.get("start", images[0][0]), entry.get("end", images[-1][0])
    frames = [f for f in images if first <= f[0] <= last]
    if [f[0] for f in frames] != list(range(first, last + 1)):
        raise RuntimeError(f"{entry['name']}: frames {first}..{last} have gaps")
    text = git(gitdir, "show", f"{entry.get('gt_commit') or newest_commit_with(gitdir, entry['gt'])}:{entry['gt']}")
    rows = rows_of(text.decode())
    if entry.get("gt_offset_full"):
        rows = rows[first - 1:last]
    annotation = ("\n".join(converted(rows, form)) + "\n").encode()
    if not len(rows) == len(frames) == entry["frames"]:
        raise RuntimeError(f"{entry['name']}: {len(frames)} frames, {len(rows)} boxes, expected {entry['frames']}")
    digest = hashlib.sha256(annotation).hexdigest()
    if digest != sha:
        raise RuntimeError(f"{entry['name']}: the annotation's SHA-256 {digest} is not the one recorded, {sha}")
    dest = out / entry["dataset"] / entry["name"]
    (dest / "img").mkdir(parents=True, exist_ok=True)
    for i, (_, name, blob) in enumerate(frames, 1):
        (dest / "img" / f"{i:06d}{os.path.splitext(name)[1].lower()}").write_bytes(git(gitdir, "cat-file", "blob", blob))
    (dest / "groundtruth_rect.txt").write_bytes(annotation)
    link = out / "all" / entry["name"]
    link.parent.mkdir(exist_ok=True)
    if not link.is_symlink():
        link.symlink_to(Path("..") / entry["dataset"] / entry["name"])
    return len(frames), digest


def reserved(path: Path) -> set[tuple[str, str]]:
    """``(benchmark, sequence)`` pairs of RESERVED.tsv, lower-cased (the UAV123 variants are one)."""
    if not path.is_file():
        raise SystemExit(f"{path} not found: the reserved list is needed to keep its sequences out (--reserved)")
    lines = [line for line in path.read_text().splitlines() if line and not line.startswith("#")]
    rows = list(csv.reader(lines[1:], delimiter="\t"))
    return {(b.split("_")[0].lower(), s.lower()) for b, s in rows}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("mirror", type=Path)
    parser.add_argument("out", type=Path)
    parser.add_argument("--manifest", type=Path, default=SHARED / "validation" / "sequences.json")
    parser.add_argument("--reserved", type=Path, default=SHARED / "RESERVED.tsv")
    parser.add_argument("--manifest-only", action="store_true", help="leave out the sequences of EXTRA")
    args = parser.parse_args(argv)
    kept_out = reserved(args.reserved)
    plan = [(e, "as_written", e["annotation_sha256"]) for e in json.loads(args.manifest.read_text())]
    plan += [] if args.manifest_only else [(e, e["format"], e["sha256"]) for e in EXTRA]
    refused = [f"{e['dataset']}/{e['name']}" for e, _, _ in plan
               if (e["dataset"].split("_")[0].lower(), e["name"].lower()) in kept_out]
    if refused:  # before anything is written
        raise SystemExit(f"reserved ({args.reserved}), not built: {', '.join(refused)}")
    totals: dict[str, list[int]] = {}
    for entry, form, sha in plan:
        try:
            frames, digest = build(entry, args.mirror, args.out, form, sha)
        except RuntimeError as exc:  # a snapshot that is not what the manifest says
            raise SystemExit(f"validation set: {exc}") from None
        totals.setdefault(entry["dataset"], []).append(frames)
        print(f"{entry['dataset']}/{entry['name']}: {frames} frames, annotation sha256 {digest}", flush=True)
    for dataset, counts in totals.items():
        print(f"{dataset}: {len(counts)} sequences, {sum(counts)} frames")
    print(f"all: {sum(len(c) for c in totals.values())} sequences, {sum(map(sum, totals.values()))} frames "
          f"-> {args.out} (read with --dataset otb --root {args.out / 'all'})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
