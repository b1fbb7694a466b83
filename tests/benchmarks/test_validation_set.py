"""benchmarks/validation_set.py on tiny git snapshots built here: a clean build, and snapshots
that are not what was recorded (issue 37, item 4): each refused in one line, with bounded reads
and nothing half-written left in OUT as if it were valid."""
import hashlib
import importlib.util
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import cv2
import numpy as np
import pytest

SCRIPT = Path(__file__).resolve().parents[2] / "benchmarks" / "validation_set.py"
_spec = importlib.util.spec_from_file_location("validation_set", SCRIPT)
vs = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(vs)

pytestmark = pytest.mark.skipif(shutil.which("git") is None, reason="needs git")

KEY = "UAV123_10fps/synthetic_1"
FRAMES = 4


def commit(work: Path) -> None:
    for command in (["add", "-A"], ["-c", "user.email=t@t", "-c", "user.name=t", "commit", "-qm", "s"]):
        subprocess.run(["git", *command], cwd=work, check=True, capture_output=True)


def sha256sum_listing(files: list[Path], names: list[str]) -> str:
    """The SHA-256 of what ``sha256sum`` prints for ``files`` written as ``names``: the reference."""
    text = "".join(f"{hashlib.sha256(f.read_bytes()).hexdigest()}  {n}\n" for f, n in zip(files, names))
    return hashlib.sha256(text.encode()).hexdigest()


@pytest.fixture
def snapshot(tmp_path) -> tuple[Path, dict]:
    """A committed repository ``someone/tracker`` (seq/img/0001.png ..., seq/gt.txt); its manifest entry."""
    work = tmp_path / "mirror" / "someone+tracker" / "repo"
    (work / "seq" / "img").mkdir(parents=True)
    rng = np.random.default_rng(0)
    files = [work / "seq" / "img" / f"{i:04d}.png" for i in range(1, FRAMES + 1)]
    for f in files:
        cv2.imwrite(str(f), rng.integers(0, 256, (6, 8, 3), dtype=np.uint8))
    annotation = "".join(f"{i},2,3,4\n" for i in range(1, FRAMES + 1))
    (work / "seq" / "gt.txt").write_text(annotation)
    subprocess.run(["git", "init", "-q"], cwd=work, check=True)
    commit(work)
    entry = {"dataset": "UAV123_10fps", "name": "synthetic_1", "repo": "someone/tracker", "img_dir": "seq/img",
             "gt": "seq/gt.txt", "start": 1, "end": FRAMES, "frames": FRAMES,
             "annotation_sha256": hashlib.sha256(annotation.encode()).hexdigest(),
             "frames_sha256": sha256sum_listing(files, [f"{i:06d}.png" for i in range(1, FRAMES + 1)])}
    return work, entry


def run(tmp_path: Path, entries: list[dict], *args: str, out: str = "out") -> str | int:
    """main() on a manifest of ``entries``: its return code, or the message it exits with."""
    (tmp_path / "manifest.json").write_text(json.dumps(entries))
    (tmp_path / "reserved.tsv").write_text("# kept out\nbenchmark\tsequence\nUAV123_10fps\tkept_out_1\n")
    argv = [str(tmp_path / "mirror"), *([str(tmp_path / out)] if out else []), "--manifest",
            str(tmp_path / "manifest.json"), "--reserved", str(tmp_path / "reserved.tsv"), "--manifest-only", *args]
    try:
        return vs.main(argv)
    except SystemExit as exc:
        assert exc.code == 2 or "\n" not in exc.code, exc.code  # 2: argparse; else one line, no traceback
        return exc.code


def nothing_of(out: Path) -> bool:
    """True when ``out`` holds no sequence folder, link or half-written folder."""
    return not out.exists() or not [p for p in out.rglob("*") if p.is_file() or p.is_symlink()]


def test_a_clean_build_is_written_and_pinned(tmp_path, snapshot, capsys):
    work, entry = snapshot
    assert run(tmp_path, [entry], out="") == 2  # argparse: neither OUT nor --print-pins
    capsys.readouterr()
    done = subprocess.run([sys.executable, str(SCRIPT), str(tmp_path / "mirror"), str(tmp_path / "out"), "--manifest",
                           str(tmp_path / "manifest.json"), "--reserved", str(tmp_path / "reserved.tsv"),
                           "--manifest-only"], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert f"{KEY}: 4 frames" in done.stdout and "all: 1 sequences, 4 frames" in done.stdout
    seq = tmp_path / "out" / "all" / "synthetic_1"
    written = sorted((seq / "img").iterdir())
    assert [p.name for p in written] == [f"{i:06d}.png" for i in range(1, FRAMES + 1)]
    assert sha256sum_listing(written, [p.name for p in written]) == entry["frames_sha256"]
    assert (seq / "groundtruth_rect.txt").read_bytes() == (work / "seq" / "gt.txt").read_bytes()
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["UAV123_10fps", "all"]  # no staging left
    assert run(tmp_path, [entry]) == 0  # again, over the first build
    # --print-pins prints the pin a trusted mirror gives and writes nothing
    capsys.readouterr()
    assert run(tmp_path, [entry], "--print-pins", out="") == 0
    assert capsys.readouterr().out == f'    "{KEY}": "{entry["frames_sha256"]}",\n'
    # a sequence without a pin is not built
    unpinned = {k: v for k, v in entry.items() if k != "frames_sha256"}
    assert "no SHA-256 of its frames is recorded; run --print-pins" in run(tmp_path, [unpinned], out="out2")
    assert nothing_of(tmp_path / "out2")
    # a reserved sequence is refused before anything is written, in any UAV123 version
    message = run(tmp_path, [entry, {**entry, "name": "kept_out_1", "dataset": "UAV123"}], out="out3")
    assert "reserved" in message and "UAV123/kept_out_1" in message and not (tmp_path / "out3").exists()
    # an annotation that is not the recorded one is an error
    assert "is not the one recorded" in run(tmp_path, [{**entry, "annotation_sha256": "0" * 64}], out="out4")


def test_an_oversize_annotation_is_refused_unread(tmp_path, snapshot, monkeypatch):
    work, entry = snapshot
    monkeypatch.setattr(vs, "ANNOTATION_BYTES", 64, raising=False)
    (work / "seq" / "gt.txt").write_text("1,2,3,4\n" * 9)  # 72 bytes
    commit(work)
    blob = subprocess.run(["git", "rev-parse", "HEAD:seq/gt.txt"], cwd=work, capture_output=True,
                          text=True).stdout.strip()
    calls = []
    real_git = vs.git
    monkeypatch.setattr(vs, "git", lambda gitdir, *args: calls.append(args) or real_git(gitdir, *args))
    message = run(tmp_path, [entry])
    assert message == ("validation set: someone/tracker: seq/gt.txt has 72 bytes, "
                       "more than the 64 an annotation may have")
    assert not [a for a in calls if blob in " ".join(a) or a[0] == "show"]  # its content was never read
    assert nothing_of(tmp_path / "out")


def test_a_tampered_frame_is_refused_and_nothing_half_written_stays(tmp_path, snapshot):
    work, entry = snapshot
    img = work / "seq" / "img"
    assert run(tmp_path, [entry]) == 0
    good = {p.name: p.read_bytes() for p in (tmp_path / "out" / KEY / "img").iterdir()}
    # an object of the store replaced by another: git reads it unchecked
    ids = [subprocess.run(["git", "rev-parse", f"HEAD:seq/img/{n:04d}.png"], cwd=work, capture_output=True,
                          text=True).stdout.strip() for n in (1, 3)]
    first, third = (work / ".git" / "objects" / i[:2] / i[2:] for i in ids)
    third.chmod(0o644)
    shutil.copyfile(first, third)
    message = run(tmp_path, [entry])
    assert f"{KEY}: someone/tracker: seq/img/0003.png: its content is not git object {ids[1]}" in message
    assert {p.name: p.read_bytes() for p in (tmp_path / "out" / KEY / "img").iterdir()} == good  # untouched
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["UAV123_10fps", "all"]
    # a newer commit with another frame: the pin catches it; nothing is written
    cv2.imwrite(str(img / "0002.png"), np.zeros((6, 8, 3), np.uint8))
    shutil.copyfile(img / "0001.png", img / "0003.png")  # a valid object again
    commit(work)
    message = run(tmp_path, [entry], out="out2")
    assert message.startswith(f"validation set: {KEY}: the SHA-256 of its frames, ")
    assert "is not the one recorded" in message
    assert nothing_of(tmp_path / "out2")


def _digitless(img: Path) -> str:
    (img / "cover.png").write_bytes((img / "0001.png").read_bytes())
    return "someone/tracker: seq/img/cover.png: the name holds no frame number"


def _symlink(img: Path) -> str:
    (img / "0004.png").unlink()
    os.symlink("0001.png", img / "0004.png")
    return "someone/tracker: seq/img/0004.png is a blob of mode 120000, not a file"


def _not_utf8(img: Path) -> str:
    with open(os.path.join(os.fsencode(img), b"\xff0005.png"), "wb") as f:
        f.write(b"x")
    return "someone/tracker: seq/img/\\xff0005.png: the name is not UTF-8"


def _huge_number(img: Path) -> str:
    (img / f"1{'0' * 29}.png").write_bytes(b"x")
    return f"someone/tracker: seq/img/1{'0' * 29}.png: the name holds no frame number (1 to 18 digits)"


@pytest.mark.parametrize("change", [_digitless, _symlink, _not_utf8, _huge_number])
def test_a_hostile_image_folder_is_refused_in_one_line(tmp_path, snapshot, change):
    work, entry = snapshot
    expected = change(work / "seq" / "img")
    commit(work)
    whole_folder = {k: v for k, v in entry.items() if k not in ("start", "end")}  # as EXTRA's are
    message = run(tmp_path, [whole_folder])
    assert message.startswith(f"validation set: {expected}"), message
    assert nothing_of(tmp_path / "out")


@pytest.mark.parametrize("limit, expected", [("FOLDER_BYTES", "seq/img is a git tree of "),
                                             ("FRAME_BYTES", "seq/img/0001.png has "),
                                             ("SEQUENCE_BYTES", "seq/img: 4 frames of ")])
def test_reads_are_bounded(tmp_path, snapshot, monkeypatch, limit, expected):
    _, entry = snapshot
    monkeypatch.setattr(vs, limit, 50, raising=False)
    message = run(tmp_path, [entry])
    assert f"someone/tracker: {expected}" in message and "more than the 50 " in message
    assert nothing_of(tmp_path / "out")


@pytest.mark.parametrize("change", [{"dataset": "../escape"}, {"name": "a/b"}, {"repo": "../../x"},
                                    {"img_dir": "seq/../seq/img"}, {"frames": 10**12}])
def test_a_manifest_entry_that_leaves_its_folders_is_refused(tmp_path, snapshot, change):
    _, entry = snapshot
    message = run(tmp_path, [{**entry, **change}])
    assert message.startswith(f"validation set: {tmp_path / 'manifest.json'}: manifest entry "), message
    assert not (tmp_path / "out").exists() and not (tmp_path / "escape").exists()


@pytest.mark.parametrize("form, content, expected", [
    ("as_written", b"1,2,3,4\n\xff\n", "seq/gt.txt is not UTF-8 text (invalid start byte at byte 8)"),
    ("as_written", None, "seq/gt.txt is a blob of mode 120000, not a file"),
    ("xywh1", b"1,2,3,4\n1,2,x,4\n", "seq/gt.txt: not xywh1 boxes: could not convert string to float: 'x'"),
    ("polygon0", b"1,2,3,4,5\n", "seq/gt.txt: not polygon0 boxes: row 1 has 5 values"),
])
def test_a_hostile_annotation_is_refused_in_one_line(tmp_path, snapshot, form, content, expected):
    work, entry = snapshot
    gt = work / "seq" / "gt.txt"
    if content is None:
        gt.unlink()
        os.symlink("img/0001.png", gt)
    else:
        gt.write_bytes(content)
    commit(work)
    with pytest.raises(vs.DatasetError) as caught:
        vs.checked(entry, tmp_path / "mirror", form, entry["annotation_sha256"])
    assert str(caught.value).startswith(f"someone/tracker: {expected}")
