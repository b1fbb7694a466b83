"""Build the validation set from fetched snapshots of public repositories (one command).

    python benchmarks/validation_set.py MIRROR OUT [--manifest M] [--reserved R]
    python benchmarks/validation_set.py MIRROR --print-pins

MIRROR holds one snapshot per repository as ``MIRROR/OWNER+NAME/repo`` (a bare git directory or
a folder holding ``.git``: what `git clone --mirror` or the library's ``fetch`` leaves). The
set is the fifteen sequences of ``../shared/data/validation/sequences.json`` (``--manifest``),
each checked against its frame count and annotation SHA-256, and the other public sequences
that file's README lists (:data:`EXTRA`), each checked against its frame count and the SHA-256
dcfkit recorded when it first built it. Every sequence's frames are checked against the SHA-256
of :data:`FRAMES_SHA256` (that of ``sha256sum *`` in its ``img`` folder; ``--print-pins`` prints
them for a trusted mirror, writing nothing), and written to a hidden folder that is renamed
into place only once they match. Reads are bounded (:data:`ANNOTATION_BYTES`, :data:`FRAME_BYTES`,
:data:`SEQUENCE_BYTES`, :data:`FOLDER_BYTES`): a snapshot that is not what was recorded is
refused in one line. No sequence of ``RESERVED.tsv`` (``--reserved``) is ever written.

Writes ``OUT/<DATASET>/<sequence>/img/000001.jpg ...`` and ``groundtruth_rect.txt`` (1-based
``x,y,w,h``, ``nan`` where the target is absent): the OTB layout, detected as such, so
``--root OUT/<DATASET>`` reads one benchmark and ``--root OUT/all`` (links to every sequence)
the whole set. Needs git. docs/results.md ("The validation set") says what it covers.
"""
from __future__ import annotations

import argparse
import csv
import hashlib
import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

from dcfkit.errors import DatasetError, clip, printable, shown

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

#: ``DATASET/name`` -> the SHA-256 of what ``sha256sum *`` prints in the sequence's ``img``
#: folder as written (``--print-pins`` on the snapshots of 2026-11-29). A manifest entry's
#: ``frames_sha256`` takes precedence.
FRAMES_SHA256 = {
    "DTB70/MountainBike6": "cdf462765acaea0fb8657b46981e5bf3de27fc0016b8973451b529f187647f5c",
    "DTB70/Surfing06": "66a8c8583a1626d977648f673716872f53ca64146fe9f0fce61a98ee90ee8867",
    "OTB/Human3": "43b8b10685c5864337e42db326df49b13cb6c889ae1e23b51eae532d417cd3c5",
    "OTB/Biker": "d54f6e28d4d522990ef4046a91a475e995189ff2eb25c2f26de9f613efcd12ac",
    "UAV123_10fps/group3_2": "81d65b111a468ae09f6b5d786583fa7ce521f3698c524ad20158d4087c424d54",
    "UAV123_10fps/wakeboard5": "3491dc35f1d9d31d80ccf0b0cb575ccc2d38a228c2393ad385107cf7ed5cac76",
    "UAV123_10fps/boat5": "565fb775353740e8b6b400207ceefc3573393ac1076abda03b21884c4042de03",
    "UAV123_10fps/car14": "bded52d3a521d59885e939afcad669c95bed907e6bee1741281aa3ed19701221",
    "UAV123_10fps/group2_2": "1b13a9fb292b05ea088dc3804a458ba2982b6417e18186adfb18771d3a14bb35",
    "UAV123_10fps/car16_2": "415bce7d13d490151abc6a889f266cd6f12a9be52e97b146fc2ad4af050076f9",
    "UAV123_10fps/wakeboard3": "ed35e38041a377751bead9716e667ed5ec23f5aed4105f51092a395e0ee4074f",
    "UAV123_10fps/person12_1": "d48fb5f277bba1f49438735da42606941c762331cc7ee4dfc2b1834a67062f23",
    "UAV123_10fps/truck2": "572b3fe59f786fefca34d8badb589515e2ca7fdd4e3540b405feed37c0f650ac",
    "UAVDT/S1001": "3ba28ff455ebfb2884d29889e25561126df2c5390f796e71d93b9ca38f3675dd",
    "UAVDT/S0310": "b39c53b122f9a2a905b66e4c72845fb098ba65138f46a0823806d0af58400873",
    "DTB70/Yacht2": "196763cfeb870e804f7dd13bc3d2cbee5f16079f8061f2e5fef0379c675687de",
    "OTB/Bird2": "8883c82a79e5eaa110a39eda0dfffe15c837b17cf0c12a0f375166ccee5acbfe",
    "OTB/DragonBaby": "61289c977116e3ae90267aa9bce7cbae9525252df7df20c0cf2687e0b0856583",
    "VOT/bag": "e0cf4f22db9f12cd6fb0aafd096198fb625ac3ab51c2c22d3a74017f756126f4",
    "VOT-LT/yamaha": "4ae45dc64557206b72de5163adee99f3c2b603f5a22f2c11f17de29cb1c9c2fe",
}

IMAGE_ENDINGS = (".jpg", ".jpeg", ".png", ".bmp")
BLOB_MODES = ("100644", "100755")  # a file; 120000 is a symbolic link, 160000 a submodule
ANNOTATION_BYTES = 1 << 20  # the largest real annotation, yamaha's 3,143 boxes, has 74 kB
FRAME_BYTES = 32 << 20  # the largest real frame has 335 kB; a 4K PNG fits
FOLDER_BYTES = 4 << 20  # git's listing of an image folder: ~100,000 names; yamaha's 3,143 take 126 kB
SEQUENCE_BYTES = 4 << 30  # the frames of one sequence; the largest real one, yamaha, has 123 MB
MAX_FRAMES = 100_000  # of one sequence; the longest real one, yamaha, has 3,143
MAX_COMMITS = 10_000  # searched for the newest commit holding a path; the snapshots have at most 288
MAX_DIGITS = 18  # of a frame number (a time stamp in milliseconds has 13)
NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]{0,99}")  # a dataset or sequence name: one folder of OUT


def git(gitdir: Path, *args: str) -> bytes:
    done = subprocess.run(["git", "--git-dir", str(gitdir), *args], capture_output=True)
    if done.returncode:
        error = done.stderr.decode(errors="replace").strip()
        raise DatasetError(f"git {printable(' '.join(args))} in {gitdir}: {clip(printable(error))}")
    return done.stdout


def snapshot(mirror: Path, repo: str) -> Path:
    """The git directory of ``repo``'s snapshot under ``mirror``."""
    base = mirror / repo.replace("/", "+") / "repo"
    for candidate in (base / ".git", base):
        if candidate.is_dir():
            return candidate
    raise SystemExit(f"{repo}: no snapshot under {base}; fetch it first")


def newest_commit_with(gitdir: Path, path: str) -> str:
    for commit in git(gitdir, "rev-list", "--all", "--date-order", f"--max-count={MAX_COMMITS}").decode().split():
        if git(gitdir, "ls-tree", commit, "--", path).strip():
            return commit
    raise DatasetError(f"{path} is in none of the newest {MAX_COMMITS} commits of {gitdir}")


def tree_entries(gitdir: Path, *args: str) -> list[tuple[str, str, str, str, bytes]]:
    """``(mode, kind, object id, size, name)`` of what ``git ls-tree -l`` lists; names as bytes."""
    found = []
    for record in git(gitdir, "ls-tree", "-l", "-z", *args).split(b"\0"):
        if record:
            meta, name = record.split(b"\t", 1)
            mode, kind, blob, size = meta.decode().split()
            found.append((mode, kind, blob, size, name))
    return found


def blob_bytes(gitdir: Path, blob: str, size: int, where: str) -> bytes:
    """The ``size`` bytes of ``blob``, checked against its id: git reads an object unchecked."""
    data = git(gitdir, "cat-file", "blob", blob)
    kind = "sha1" if len(blob) == 40 else "sha256"
    if len(data) != size or hashlib.new(kind, b"blob %d\0" % len(data) + data).hexdigest() != blob:
        raise DatasetError(f"{where}: its content is not git object {blob}: the snapshot is damaged or tampered with")
    return data


def refuse_unless_file(mode: str, kind: str, path: str) -> None:
    if kind != "blob" or mode not in BLOB_MODES:
        raise DatasetError(f"{path} is a {kind} of mode {mode}, not a file (a symbolic link or submodule?)")


def frame_name(mode: str, kind: str, size: str, raw: bytes, where: str) -> tuple[int, str]:
    """An image file's (frame number, name); refused in one line if it cannot be a frame."""
    path = f"{where}/{printable(raw.decode(errors='backslashreplace'))}"
    try:
        name = raw.decode()
    except UnicodeDecodeError:
        raise DatasetError(f"{path}: the name is not UTF-8") from None
    refuse_unless_file(mode, kind, path)
    digits = re.findall(r"[0-9]+", os.path.splitext(name)[0])
    if not digits or len(digits[-1]) > MAX_DIGITS:
        raise DatasetError(f"{path}: the name holds no frame number (1 to {MAX_DIGITS} digits)")
    if int(size) > FRAME_BYTES:
        raise DatasetError(f"{path} has {size} bytes, more than the {FRAME_BYTES} a frame may have")
    return int(digits[-1]), name


def image_blobs(gitdir: Path, commit: str, folder: str, repo: str) -> list[tuple[int, str, str, int]]:
    """``(frame number, file name, blob, size)`` of the images in ``folder``, by frame number."""
    listing = int(git(gitdir, "cat-file", "-s", f"{commit}:{folder}"))
    if listing > FOLDER_BYTES:
        raise DatasetError(f"{repo}: {folder} is a git tree of {listing} bytes, more than the {FOLDER_BYTES} "
                           f"an image folder may have (about {MAX_FRAMES} names)")
    endings = tuple(e.encode() for e in IMAGE_ENDINGS)
    return sorted((*frame_name(mode, kind, size, raw, f"{repo}: {folder}"), blob, int(size))
                  for mode, kind, blob, size, raw in tree_entries(gitdir, f"{commit}:{folder}")
                  if raw.lower().endswith(endings))


def annotation_text(gitdir: Path, commit: str, path: str, repo: str) -> str:
    """The annotation file ``path``, its size checked before it is read."""
    found = tree_entries(gitdir, commit, "--", path)
    if len(found) != 1:
        raise DatasetError(f"{repo}: {path} is not one file of commit {commit}")
    mode, kind, blob, size, _ = found[0]
    refuse_unless_file(mode, kind, f"{repo}: {path}")
    if int(size) > ANNOTATION_BYTES:
        raise DatasetError(f"{repo}: {path} has {size} bytes, more than the {ANNOTATION_BYTES} an annotation may have")
    try:
        return blob_bytes(gitdir, blob, int(size), f"{repo}: {path}").decode()
    except UnicodeDecodeError as exc:
        raise DatasetError(f"{repo}: {path} is not UTF-8 text ({exc.reason} at byte {exc.start})") from None


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
    for n, r in enumerate(rows, 1):
        v = [float(x) for x in r]
        if len(v) < 4 or form == "polygon0" and len(v) % 2:
            raise ValueError(f"row {n} has {len(v)} values")
        if any(x != x for x in v):  # NaN: the target is absent
            out.append("nan,nan,nan,nan")
            continue
        if form == "polygon0":
            xs, ys = v[0::2], v[1::2]
            v = [min(xs), min(ys), max(xs) - min(xs), max(ys) - min(ys)]
        shift = 1.0 if form in ("xywh0", "polygon0") else 0.0
        out.append(",".join(f"{x:.6g}" for x in (v[0] + shift, v[1] + shift, v[2], v[3])))
    return out


def checked(entry: dict, mirror: Path, form: str, sha: str) -> tuple[Path, list[tuple[int, str, str, int]], bytes]:
    """One sequence's git directory, frames ``(number, name, blob, size)`` and converted
    annotation, checked against its frame count and the annotation's SHA-256 ``sha``."""
    repo, folder, expected = entry["repo"], entry["img_dir"], entry["frames"]
    gitdir = snapshot(mirror, repo)
    images = image_blobs(gitdir, entry.get("commit") or newest_commit_with(gitdir, folder), folder, repo)
    if not images:
        raise DatasetError(f"{repo}: no images ({', '.join(IMAGE_ENDINGS)}) in {folder}")
    first, last = entry.get("start", images[0][0]), entry.get("end", images[-1][0])
    if last - first + 1 != expected:  # before range(first, last) is made: a name may hold any number
        raise DatasetError(f"{entry['name']}: frames {first}..{last} in {repo}: {folder}, expected {expected}")
    frames = [f for f in images if first <= f[0] <= last]
    if [f[0] for f in frames] != list(range(first, last + 1)):
        raise DatasetError(f"{entry['name']}: frames {first}..{last} in {repo}: {folder} have gaps or repeats")
    total = sum(f[3] for f in frames)
    if total > SEQUENCE_BYTES:  # checked before anything is written
        raise DatasetError(f"{repo}: {folder}: {len(frames)} frames of {total} bytes, more than the "
                           f"{SEQUENCE_BYTES} a sequence may have")
    text = annotation_text(gitdir, entry.get("gt_commit") or newest_commit_with(gitdir, entry["gt"]), entry["gt"], repo)
    rows = rows_of(text)
    if entry.get("gt_offset_full"):
        rows = rows[first - 1:last]
    try:
        annotation = ("\n".join(converted(rows, form)) + "\n").encode()
    except ValueError as exc:
        raise DatasetError(f"{repo}: {entry['gt']}: not {form} boxes: {clip(printable(exc))}") from None
    if not len(rows) == len(frames) == expected:
        raise DatasetError(f"{entry['name']}: {len(frames)} frames, {len(rows)} boxes, expected {expected}")
    digest = hashlib.sha256(annotation).hexdigest()
    if digest != sha:
        raise DatasetError(f"{entry['name']}: the annotation's SHA-256 {digest} is not the one recorded, {sha}")
    return gitdir, frames, annotation


def frames_sha256(gitdir: Path, frames: list, img: Path | None, where: str) -> str:
    """Write ``frames`` as ``img/000001.jpg ...`` (``img`` None: nowhere); the SHA-256 of what
    ``sha256sum *`` prints for them, each frame checked against its git object id."""
    listing = hashlib.sha256()
    for i, (_, name, blob, size) in enumerate(frames, 1):
        data = blob_bytes(gitdir, blob, size, f"{where}/{name}")
        written = f"{i:06d}{os.path.splitext(name)[1].lower()}"
        listing.update(f"{hashlib.sha256(data).hexdigest()}  {written}\n".encode())
        if img is not None:
            (img / written).write_bytes(data)
    return listing.hexdigest()


def build(entry: dict, gitdir: Path, frames: list, annotation: bytes, out: Path, pin: str) -> None:
    """Write one sequence into a hidden folder of ``out``, renamed into place once its frames
    match ``pin``; removed if they do not, so nothing half-written is left as if valid."""
    key = f"{entry['dataset']}/{entry['name']}"
    staging = out / f".{entry['dataset']}.{entry['name']}.partial"
    shutil.rmtree(staging, ignore_errors=True)  # a build killed before
    (staging / "img").mkdir(parents=True)
    try:
        digest = frames_sha256(gitdir, frames, staging / "img", f"{key}: {entry['repo']}: {entry['img_dir']}")
        if digest != pin:
            raise DatasetError(f"{key}: the SHA-256 of its frames, {digest}, is not the one recorded, {pin}: "
                               f"a frame differs from the snapshot dcfkit pinned")
        (staging / "groundtruth_rect.txt").write_bytes(annotation)
        dest = out / entry["dataset"] / entry["name"]
        if dest.is_symlink() or dest.is_file():
            dest.unlink()
        elif dest.exists():
            shutil.rmtree(dest)  # an earlier build of this sequence
        dest.parent.mkdir(exist_ok=True)
        staging.rename(dest)
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    link = out / "all" / entry["name"]
    link.parent.mkdir(exist_ok=True)
    if not link.is_symlink():
        link.symlink_to(Path("..") / entry["dataset"] / entry["name"])


def check_entry(entry: dict) -> None:
    """Refuse an entry whose names would leave OUT, MIRROR or the repository's tree, or whose
    frame count is absurd, before anything is read."""
    where = f"manifest entry {shown(entry.get('dataset'))}/{shown(entry.get('name'))}"
    names = [entry.get("dataset"), entry.get("name"), *str(entry.get("repo")).split("/", 1)]
    if not all(isinstance(n, str) and NAME.fullmatch(n) for n in names):
        raise DatasetError(f"{where}: dataset, name and the two parts of repo must be plain names "
                           f"({NAME.pattern}), repo {shown(entry.get('repo'))}")
    for key in ("img_dir", "gt"):
        if not isinstance(entry.get(key), str) or any(p in ("", ".", "..") for p in entry[key].split("/")):
            raise DatasetError(f"{where}: {key} must be a path in the repository without '.' or '..', "
                               f"got {shown(entry.get(key))}")
    if not (isinstance(entry.get("frames"), int) and 1 <= entry["frames"] <= MAX_FRAMES) or \
            not all(isinstance(entry.get(k, 1), int) for k in ("start", "end")):
        raise DatasetError(f"{where}: frames must be a count of 1 to {MAX_FRAMES}, start and end frame numbers")


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
    parser.add_argument("out", type=Path, nargs="?")
    parser.add_argument("--manifest", type=Path, default=SHARED / "validation" / "sequences.json")
    parser.add_argument("--reserved", type=Path, default=SHARED / "RESERVED.tsv")
    parser.add_argument("--manifest-only", action="store_true", help="leave out the sequences of EXTRA")
    parser.add_argument("--print-pins", action="store_true",
                        help="print each sequence's frames SHA-256 for FRAMES_SHA256 (a trusted mirror); write nothing")
    args = parser.parse_args(argv)
    if (args.out is None) != args.print_pins:
        parser.error("give OUT, or --print-pins without it")
    kept_out = reserved(args.reserved)
    plan = [(e, "as_written", e.get("annotation_sha256")) for e in json.loads(args.manifest.read_text())]
    plan += [] if args.manifest_only else [(e, e["format"], e["sha256"]) for e in EXTRA]
    try:
        for entry, _, _ in plan:
            check_entry(entry)
    except DatasetError as exc:
        raise SystemExit(f"validation set: {args.manifest}: {exc}") from None
    refused = [f"{e['dataset']}/{e['name']}" for e, _, _ in plan
               if (e["dataset"].split("_")[0].lower(), e["name"].lower()) in kept_out]
    if refused:  # before anything is written
        raise SystemExit(f"reserved ({args.reserved}), not built: {', '.join(refused)}")
    totals: dict[str, list[int]] = {}
    for entry, form, sha in plan:
        key = f"{entry['dataset']}/{entry['name']}"
        try:
            gitdir, frames, annotation = checked(entry, args.mirror, form, sha)
            if args.print_pins:
                pin = frames_sha256(gitdir, frames, None, f"{key}: {entry['repo']}: {entry['img_dir']}")
                print(f'    "{key}": "{pin}",', flush=True)
                continue
            pin = entry.get("frames_sha256") or FRAMES_SHA256.get(key)
            if pin is None:
                raise DatasetError(f"{key}: no SHA-256 of its frames is recorded; run --print-pins on a trusted "
                                   f"mirror and add it to FRAMES_SHA256")
            build(entry, gitdir, frames, annotation, args.out, pin)
        except DatasetError as exc:  # a snapshot that is not what the manifest says
            raise SystemExit(f"validation set: {exc}") from None
        totals.setdefault(entry["dataset"], []).append(len(frames))
        print(f"{key}: {len(frames)} frames, annotation sha256 {hashlib.sha256(annotation).hexdigest()}, "
              f"frames sha256 {pin}", flush=True)
    for dataset, counts in totals.items():
        print(f"{dataset}: {len(counts)} sequences, {sum(counts)} frames")
    if totals:
        print(f"all: {sum(len(c) for c in totals.values())} sequences, {sum(map(sum, totals.values()))} frames "
              f"-> {args.out} (read with --root {args.out / 'all'})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
