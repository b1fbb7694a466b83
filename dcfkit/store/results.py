"""The results store: one folder of per-sequence result files that cannot be silently damaged.

Per sequence: ``<seq>.txt`` (1-based ``x,y,w,h`` per frame, ``%.3f``: the toolkits' format),
``<seq>.time``, ``<seq>.confidence``, and the sidecar ``<seq>.json`` (run key, checksums,
config, versions), written last to mark it done; ``<seq>.error`` instead when the tracker
raised (docs/evaluation.md, "Running", has every field). Every file is written whole or not
at all (:mod:`dcfkit.store.files`), and a result is used only while its ``.txt`` has the
checksum its sidecar recorded (:meth:`ResultStore.problem`).
"""
from __future__ import annotations

import contextlib
import dataclasses
import hashlib
import json
import logging
import os
import re
import traceback
from pathlib import Path
from typing import Iterable

import numpy as np

from dcfkit.datasets import DatasetError, Sequence, read_boxes
from dcfkit.errors import clip, shown
from dcfkit.store.files import (
    StoreError,
    atomic_write,
    checksum,
    format_boxes,
    format_confidence,
    format_times,
    make_dir,
    read_json,
)
from dcfkit.store.provenance import json_default, now, without_home

log = logging.getLogger(__name__)

# the endings of a sequence's files in a store; none is an ending of another
BOXES_END, SIDECAR_END, ERROR_END, TIME_END, CONFIDENCE_END = ".txt", ".json", ".error", ".time", ".confidence"
TOOLKIT_TIME_SUFFIX, TOOLKIT_CONFIDENCE_SUFFIX = "_time", "_confidence"  # <sequence>_time.txt, as toolkits write


# --------------------------------------------------------------------------- the store


@dataclasses.dataclass(frozen=True, eq=False)
class SequenceResult:
    """A tracker's result on one sequence: ``boxes`` ``(N, 4) float64`` 0-based;
    ``times`` ``(N,) float64`` seconds per frame and ``fps`` when known (None for imports);
    ``platform`` the :func:`dcfkit.store.platforms.record` of the run when its sidecar has one;
    ``resets`` the 1-based ``starts`` and ``failures`` of a reset-based run
    (:mod:`dcfkit.experiments.reset`); ``timing`` how its speed was measured
    (:mod:`dcfkit.store.timing`; None in sidecars from before it was recorded)."""

    boxes: np.ndarray
    times: np.ndarray | None = None
    fps: float | None = None
    run_key: str | None = None
    platform: dict | None = None
    resets: dict | None = None
    timing: dict | None = None


class ResultStore:
    """The result files of one tracker configuration: ``folder/<sequence>.{txt,json,time,confidence,error}``."""

    def __init__(self, folder):
        self.folder = Path(folder)

    def boxes_path(self, name: str) -> Path:
        return self.folder / f"{name}{BOXES_END}"

    def sidecar_path(self, name: str) -> Path:
        return self.folder / f"{name}{SIDECAR_END}"

    def error_path(self, name: str) -> Path:
        return self.folder / f"{name}{ERROR_END}"

    def time_path(self, name: str) -> Path:
        return self.folder / f"{name}{TIME_END}"

    def confidence_path(self, name: str) -> Path:
        return self.folder / f"{name}{CONFIDENCE_END}"

    _WRITTEN = (boxes_path, time_path, confidence_path)  # the files a finished run writes besides its sidecar
    _RECORDS = (error_path, sidecar_path)  # JSON naming their run

    def _written(self, name: str) -> tuple[Path, ...]:
        return tuple(path_of(self, name) for path_of in self._WRITTEN)

    def file_names(self, name: str) -> list[str]:
        return [p.name for p in (*self._written(name), self.sidecar_path(name), self.error_path(name))]

    def sidecar(self, name: str) -> dict | None:
        return read_json(self.sidecar_path(name))

    def status(self, seq: Sequence, key: str, meta: dict | None = None) -> str:
        """``done`` (complete, intact, from run ``key`` on ``seq``'s current data: :meth:`stale`),
        ``damaged`` (its sidecar is ``key``'s but the sidecar or the boxes file is not what was
        written), ``failed`` (``key`` raised) or ``missing`` (an intact run of another length, a
        ``--max-frames`` smoke run's or a full one's, is missing too). ``meta``: the sidecar, if read."""
        meta = self.sidecar(seq.name) if meta is None else meta
        if meta is not None and meta.get("run_key") == key:
            if "init_box" not in meta or self.stale(seq.name, meta, seq) is not None:
                return "missing"  # a corrected annotation, or another benchmark's sequence of that name: run again
            if self.problem(seq.name, meta) is not None:
                return "damaged"
            return "done" if meta["frames"] == len(seq) else "missing"
        error = read_json(self.error_path(seq.name))
        return "failed" if error is not None and error.get("run_key") == key and same_data(error, seq) else "missing"

    def stale(self, name: str, meta: dict, seq: Sequence) -> str | None:
        """Why the intact stored run of ``name`` does not stand for ``seq`` as it is now (it
        started from another first box, or ran on other data), or None; sidecars without the
        field (older dcfkit) are trusted."""
        if "init_box" in meta and not _same_box(meta["init_box"], seq.init_box):
            return (f"{self.sidecar_path(name)}: its run started from the box {meta['init_box']!r:.80}, and the "
                    f"sequence now starts from {[float(v) for v in seq.init_box]} (a corrected annotation)")
        if not same_data(meta, seq):
            return (f"{self.sidecar_path(name)}: its run was made on other data (the sequence's ground truth or "
                    f"frames have changed since)")
        return None

    def other_length(self, run: Sequence, meta: dict | None) -> int | None:
        """The frame count of ``run``'s intact stored result (sidecar ``meta``) if it is not ``run``'s, else None."""
        if meta is None or meta.get("frames") == len(run) or self.problem(run.name, meta) is not None:
            return None
        return meta["frames"]

    def refuse_to_shorten(self, run: Sequence, meta: dict | None = None) -> None:
        """A :class:`DatasetError` if ``run`` is cut (:meth:`Sequence.head`) and an intact stored
        run of it has more frames: a smoke run (``--max-frames``) must never cost the full
        results. A sequence shortened or corrected in its folder is recomputed, as other data is."""
        if not run.cut:
            return
        frames = self.other_length(run, self.sidecar(run.name) if meta is None else meta) or 0
        if frames > len(run):
            raise DatasetError(
                f"{self.boxes_path(run.name)} holds an intact run of {frames} frames and this run of {run.name!r} has "
                f"{len(run)} (--max-frames): it is not replaced; write this run to another --out, or remove those "
                f"results to replace them")

    def is_done(self, seq: Sequence, key: str) -> bool:
        return self.status(seq, key) == "done"

    def problem(self, name: str, meta: dict, frames: int | None = None) -> str | None:
        """Why the stored result of sequence ``name`` (sidecar ``meta``; ``frames`` long, if
        known) cannot be used, or None. Results written by dcfkit < 0.4 have no checksum:
        their lines are checked against the format dcfkit wrote instead."""
        try:
            _check_sidecar(meta)
        except (TypeError, ValueError) as exc:
            return f"{self.sidecar_path(name)} is malformed ({exc})"
        path = self.boxes_path(name)
        try:
            data = path.read_bytes()
        except OSError as exc:
            return f"cannot read {path} ({exc.strerror})"
        if "sha256" in meta:
            if meta["sha256"] != checksum(data) or data.count(b"\n") != meta["frames"]:
                return f"{path} is not the file its run wrote (cut short or edited)"
        else:
            lines = data.splitlines(keepends=True)
            if len(lines) != meta["frames"] or not all(_RESULT_LINE.fullmatch(line) for line in lines):
                return f"{path} (written by dcfkit < 0.4, without a checksum) is not as its run wrote it"
        if frames is not None and meta["frames"] != frames:
            return (f"{path} holds a run of {meta['frames']} frames and the sequence has {frames} (the results of "
                    f"an eval --max-frames N are scored with the same --max-frames)")
        return None

    def write(self, seq: Sequence, boxes: np.ndarray, meta: dict, times: np.ndarray | None = None,
              confidence: np.ndarray | None = None) -> None:
        """Store a finished run: boxes, the ``times`` and ``confidence`` files (each left out,
        and any older one removed, when None), then the sidecar (``meta`` plus the checksums)."""
        text = format_boxes(boxes)
        with contextlib.suppress(FileNotFoundError):
            self.sidecar_path(seq.name).unlink()  # an older sidecar must never describe new boxes
        atomic_write(self.boxes_path(seq.name), text)
        meta = {**meta, "data_identity": data_identity(seq), "frames": len(boxes), "sha256": checksum(text.encode())}
        for field, path, data, form in (("time_sha256", self.time_path(seq.name), times, format_times),
                                        ("confidence_sha256", self.confidence_path(seq.name), confidence,
                                         format_confidence)):
            meta.pop(field, None)
            if data is None:
                with contextlib.suppress(FileNotFoundError):
                    path.unlink()
                continue
            extra = form(data)
            atomic_write(path, extra)
            meta[field] = checksum(extra.encode())
        atomic_write(self.sidecar_path(seq.name), json.dumps(meta, indent=1, default=json_default) + "\n")
        with contextlib.suppress(FileNotFoundError):
            self.error_path(seq.name).unlink()

    def write_failure(self, seq: Sequence, record: dict, exc: BaseException) -> None:
        """Store a failed run (removing any results, which another config may have left)."""
        record = {**record, "sequence": seq.name, "dataset": seq.dataset, "data_identity": data_identity(seq),
                  "type": type(exc).__name__,
                  "traceback": without_home("".join(traceback.format_exception(exc))), "time": now()}
        for stale in (self.sidecar_path(seq.name), *self._written(seq.name)):
            with contextlib.suppress(FileNotFoundError):
                stale.unlink()
        make_dir(self.folder)
        atomic_write(self.error_path(seq.name), json.dumps(record, indent=1, default=json_default) + "\n")

    def copy_run(self, source: "ResultStore", name: str, source_name: str | None = None) -> None:
        """Make run ``name`` here what run ``source_name`` (default ``name``) is in ``source``
        (the same run key's run, made once for both), file by file as :meth:`write` and
        :meth:`write_failure` order them: the sidecar removed first and written last, each file
        written whole; a file ``source`` lacks, removed. A run copied under another name (OPE's
        run as TRE's first) has that name as its sidecar's ``sequence``."""
        source_name = name if source_name is None else source_name
        with contextlib.suppress(FileNotFoundError):
            self.sidecar_path(name).unlink()
        make_dir(self.folder)
        for path_of in (*self._WRITTEN, *self._RECORDS):
            path, origin = path_of(self, name), path_of(source, source_name)
            try:
                data = origin.read_bytes()
            except FileNotFoundError:
                with contextlib.suppress(FileNotFoundError):
                    path.unlink()
                continue
            except OSError as exc:
                raise StoreError(f"cannot read {clip(str(origin))}: {exc.strerror}") from None
            renamed = path_of in self._RECORDS and source_name != name
            atomic_write(path, _renamed(data, name, origin) if renamed else data)

    def load(self, sequences: Iterable[Sequence | str]) -> dict[str, SequenceResult]:
        """Intact results for ``sequences`` (names or :class:`Sequence`); others (not run,
        failed, damaged, malformed, and for a :class:`Sequence` of another length, or
        :meth:`stale`: each but the first two logged) are left out. A
        :class:`DatasetError` if the intact results come from different configs."""
        results, keys = {}, {}
        for seq in sequences:
            name = seq if isinstance(seq, str) else seq.name
            meta = self.sidecar(name)
            if meta is None or not self.boxes_path(name).is_file():
                continue
            problem = self.problem(name, meta, None if isinstance(seq, str) else len(seq))
            if problem is None and not isinstance(seq, str):
                problem = self.stale(name, meta, seq)
            if problem is not None:
                log.warning("%s: left out; run it again to recompute %r", problem, name)
                continue
            key = meta.get("run_key", meta.get("config_hash"))  # config_hash: dcfkit < 0.4
            results[name] = SequenceResult(read_boxes(self.boxes_path(name)), _times(meta),
                                           None if meta.get("fps") is None else float(meta["fps"]), key,
                                           meta.get("platform") if isinstance(meta.get("platform"), dict) else None,
                                           meta.get("resets"),
                                           meta.get("timing") if isinstance(meta.get("timing"), dict) else None)
            keys.setdefault(key, []).append(name)
        if len(keys) > 1:
            detail = "; ".join(f"{k}: {', '.join(v[:5])}{' ...' if len(v) > 5 else ''}" for k, v in keys.items())
            raise DatasetError(
                f"results in {self.folder} mix {len(keys)} configurations ({detail}); rerun "
                f"`dcfkit eval` with one config, or give the other config a different 'name' (a key also "
                f"changes with dcfkit's version and box code: rerunning the eval recomputes the older runs)")
        return results


def _renamed(record: bytes, name: str, path: Path) -> bytes:
    """A sidecar's or failure record's JSON with ``name`` as its ``sequence``."""
    try:
        found = json.loads(record)
    except ValueError:
        raise StoreError(f"cannot read {clip(str(path))}: not JSON") from None
    return (json.dumps({**found, "sequence": name}, indent=1, default=json_default) + "\n").encode()


def data_identity(seq: Sequence) -> str:
    """What identifies a sequence's data, without decoding an image: a digest of its whole ground
    truth and of its frames' file names and sizes. Two benchmark folders may hold sequences of one
    name, length and first box; their results must not stand for each other. The ground truth is
    rounded to 1e-6 px: a box a layout computes (vot_area's polygon norms) may differ in its last
    bit between BLAS builds, and must not make one machine's results another data's."""
    digest = hashlib.sha256(np.ascontiguousarray(np.round(seq.ground_truth, 6) + 0.0, dtype="<f8").tobytes())
    for frame in seq.frames:
        try:
            size = os.stat(frame).st_size
        except OSError:  # an unreadable frame: the run fails on it, and says so
            size = -1
        digest.update(f"{frame.name}\0{size}\n".encode("utf-8", "surrogateescape"))
    return digest.hexdigest()[:16]


def _same_box(stored, box: np.ndarray) -> bool:
    """Whether a sidecar's ``init_box`` is ``box`` (NaN for NaN: a reset-based run's frame 1 may have none)."""
    try:
        return np.array_equal(np.asarray(stored, dtype=np.float64), box, equal_nan=True)
    except (TypeError, ValueError):
        return False


def same_data(record: dict, seq: Sequence) -> bool:
    """Whether a sidecar or failure ``record`` was made on ``seq``'s data; records of dcfkit
    <= 0.9.0 have no identity and are trusted, as they were (docs/evaluation.md)."""
    return "data_identity" not in record or record["data_identity"] == data_identity(seq)


_NUMBER = rb"(?:nan|-?\d+\.\d{3})"
_RESULT_LINE = re.compile(_NUMBER + rb"(?:," + _NUMBER + rb"){3}\n")  # format_boxes's %.3f lines


def _check_sidecar(meta: dict) -> None:
    """A :class:`ValueError` or :class:`TypeError` naming the first field of a results
    sidecar that has the wrong type."""
    checks = {"frames": lambda v: isinstance(v, int) and not isinstance(v, bool) and v >= 0,
              "sha256": lambda v: isinstance(v, str), "time_sha256": lambda v: isinstance(v, str),
              "confidence_sha256": lambda v: isinstance(v, str),
              "run_key": lambda v: isinstance(v, str), "config_hash": lambda v: isinstance(v, str),
              "fps": lambda v: v is None or (isinstance(v, (int, float)) and not isinstance(v, bool)),
              "times": lambda v: isinstance(v, list) and all(isinstance(t, (int, float)) for t in v),
              "resets": lambda v: isinstance(v, dict) and all(
                  isinstance(v.get(k), list) and all(isinstance(i, int) and not isinstance(i, bool) and 1 <= i <= frames
                                                     for i in v[k]) for k in ("starts", "failures"))}
    if not isinstance(meta.get("frames"), int):
        raise ValueError("no frame count")
    frames = meta["frames"]
    for field, ok in checks.items():
        if field in meta and not ok(meta[field]):
            raise TypeError(f"{field} is {meta[field]!r:.60}")


def _times(meta: dict) -> np.ndarray | None:
    times = np.asarray(meta.get("times", []), dtype=np.float64).reshape(-1)
    return times if times.size else None


def load_results(out_dir, tracker_name: str, sequences: Iterable[Sequence | str]) -> dict[str, SequenceResult]:
    """Intact results of ``tracker_name`` under ``out_dir`` (:meth:`ResultStore.load`)."""
    folder = Path(out_dir) / tracker_name
    if not folder.is_dir():
        raise DatasetError(f"no results folder for tracker {shown(tracker_name)}: {clip(str(folder))}")
    return ResultStore(folder).load(sequences)


def result_files(folder) -> dict[str, Path]:
    """``{sequence: folder/<sequence>.txt}``; a ``*_time.txt`` or ``*_confidence.txt`` (the
    timings and confidences of some toolkits and of dcfkit < 0.7) is left out unless a dcfkit
    sidecar says it is a sequence's boxes. A :class:`DatasetError` if ``folder`` is not a folder."""
    folder = Path(folder)
    if not folder.is_dir():
        raise DatasetError(f"results folder not found: {clip(str(folder))}")
    return {p.stem: p for p in sorted(folder.glob(f"*{BOXES_END}"))
            if not p.stem.endswith((TOOLKIT_TIME_SUFFIX, TOOLKIT_CONFIDENCE_SUFFIX))
            or p.with_suffix(SIDECAR_END).is_file()}


def read_confidence(path, sha256: str | None = None) -> np.ndarray:
    """``(N,) float64`` long-term presence scores of a ``<seq>.confidence`` file, one line a frame:
    column 3 (``score``) of ``peak,apce,score`` lines, else column 1 (``peak``) of the ``peak,apce``
    lines earlier runs wrote; ``nan`` where the tracker gave none. A :class:`DatasetError` naming the
    file, and the line, if it cannot be read, differs from the ``sha256`` its sidecar recorded, or a
    line is not 2 or 3 numbers (as many as the first line's)."""
    path = Path(path)
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise DatasetError(f"cannot read {clip(str(path))}: {exc.strerror}") from None
    if sha256 is not None and checksum(data) != sha256:
        raise DatasetError(f"{clip(str(path))} is not the file its run wrote (cut short or edited)")
    lines = data.decode("utf-8", "replace").split("\n")
    lines = lines[:-1] if lines[-1] == "" else lines
    rows, width = [], None
    for number, line in enumerate(lines, 1):
        fields = line.split(",")
        try:
            if len(fields) not in (2, 3) or len(fields) != (width or len(fields)):
                raise ValueError
            values = [float(f) for f in fields]
        except ValueError:
            raise DatasetError(f"{clip(str(path))}, line {number}: {shown(line)} is not "
                               f"{'2 or 3' if width is None else width} comma-separated numbers "
                               f"(peak,apce,score or peak,apce)") from None
        rows.append(values[2] if len(values) == 3 else values[0])
        width = len(fields)
    return np.array(rows, dtype=np.float64)


def import_results(folder) -> dict[str, SequenceResult]:
    """Per-sequence result files of another tracker: ``folder/<sequence>.txt``, 1-based
    ``x,y,w,h`` separated by commas, tabs or spaces. Returns 0-based boxes, no timings."""
    return {name: SequenceResult(read_boxes(path)) for name, path in result_files(folder).items()}
