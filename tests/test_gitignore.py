"""What the README's and docs' commands write into a checkout is ignored by git."""
from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
# --out of the commands that write files; a report's default folder is OUT_report beside OUT
WRITES = re.compile(r"dcfkit (eval|ablate|search|track|report)\b[^\n`|]*")
OUTPUT = re.compile(r"--(?:out|save-video)[ =](\S+)")


def written_paths() -> set[str]:
    """Relative outputs of the documented commands, folders ending in ``/`` (placeholders in capitals left out)."""
    found = set()
    for doc in DOCS:
        for match in WRITES.finditer(doc.read_text(encoding="utf-8")):
            command, line = match.group(1), match.group(0).split(" #")[0]  # not a comment's words
            outs = OUTPUT.findall(line) if command != "report" else line.split()[2:3]
            for out in outs:
                if out.isupper() or out.startswith(("/", "-", "..", "http")) or not re.fullmatch(r"[\w./-]+", out):
                    continue
                if command == "track":  # files
                    found.add(out)
                else:  # folders, and the report's beside them
                    found |= {out.rstrip("/") + "/", out.rstrip("/") + "_report/"}
    return found


@pytest.mark.skipif(shutil.which("git") is None or not (ROOT / ".git").exists(), reason="needs git and a checkout")
def test_documented_outputs_are_ignored():
    paths = written_paths()
    assert {"results/", "results_report/", "boxes.txt", "out.mp4"} <= paths  # the scan finds the README's own
    ignored = subprocess.run(["git", "-C", str(ROOT), "check-ignore", "--no-index", "--stdin"], input="\n".join(
        sorted(paths)) + "\n", capture_output=True, text=True).stdout.split()
    assert sorted(paths - set(ignored)) == []
