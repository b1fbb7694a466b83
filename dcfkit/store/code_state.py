"""Which code computed a result's boxes: a digest of the dcfkit source files that decide them
(part of every run key), and the git state a non-editable install was built from.

A changed tracker file without a version bump gets new run keys, so old boxes are never reused
for it; a changed report, command line or results bookkeeping keeps them (docs/evaluation.md,
"Run key"). The digest is computed from the files this process imports dcfkit from, once: the
same source gives the same digest as a checkout, an editable install and ``pip install .``.
"""
from __future__ import annotations

import functools
import hashlib
import json
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1]

# the parts of dcfkit that change no box: they read and score results, parse commands, or
# record where results came from; everything else (tracker, components, numerics, config
# parsing, datasets, experiments, the frame loop, the box file format, ...) is in the digest
NOT_BOX_CODE = ("_build_hook.py", "ablation", "analysis", "autosearch", "cli", "configs",
                "running/checks.py", "running/evaluation.py", "running/layout.py", "running/plan.py",
                "running/progress.py", "running/scheduler.py", "store/__init__.py", "store/claims.py",
                "store/code_state.py", "store/platforms.py", "store/provenance.py", "store/results.py",
                "store/timing.py")
CODE_FILES = (".py", ".tsv")  # sources and the tables they read; configs enter the key resolved
BUILT_SOURCE = "_source.json"  # written by dcfkit/_build_hook.py into a built wheel


def code_digest(package: Path) -> str:
    """16 hex digits of SHA-256 over the relative path and bytes (line endings read as ``\\n``)
    of every ``.py`` and ``.tsv`` file under ``package`` but :data:`NOT_BOX_CODE`, in path order."""
    digest = hashlib.sha256()
    for path in sorted(p for p in Path(package).rglob("*") if p.suffix in CODE_FILES and p.is_file()):
        name = path.relative_to(package).as_posix()
        if any(name == part or name.startswith(part + "/") for part in NOT_BOX_CODE):
            continue
        digest.update(f"{name}\0".encode("utf-8", "surrogateescape"))
        digest.update(path.read_bytes().replace(b"\r\n", b"\n"))
        digest.update(b"\0")
    return digest.hexdigest()[:16]


@functools.lru_cache(maxsize=1)
def box_code() -> str:
    """:func:`code_digest` of the dcfkit this process runs (part of every run key)."""
    return code_digest(PACKAGE)


def built_source(package: Path = PACKAGE) -> dict | None:
    """``{"commit", "dirty"}`` of the checkout a wheel of ``package`` was built from (``pip
    install .``), as the build recorded it in ``_source.json``; None if it recorded none."""
    try:
        found = json.loads((package / BUILT_SOURCE).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if not isinstance(found, dict) or not isinstance(found.get("commit"), str):
        return None
    return {"commit": found["commit"], "dirty": found.get("dirty") if isinstance(found.get("dirty"), bool) else None}
