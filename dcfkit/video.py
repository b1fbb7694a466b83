"""Reading frames (video file or image folder) and writing annotated videos."""
from __future__ import annotations

import math
import os
import re
import warnings
from pathlib import Path
from typing import Iterator

import cv2
import numpy as np

from .datasets import read_frame
from .datasets.base import jpeg_damage, jpeg_decodable
from .errors import InputError, clip, shown
from .limits import IMAGE_PIXELS_VARIABLE, max_image_pixels

IMAGE_SUFFIXES = (".jpg", ".jpeg", ".png", ".bmp", ".tif", ".tiff")
COLOURS = ((0, 0, 255), (0, 255, 255), (255, 160, 0), (255, 0, 255), (255, 255, 255))  # BGR


def _natural_key(path: Path) -> list:
    """'frame2.jpg' before 'frame10.jpg': digit runs compare as numbers."""
    return [int(part) if part.isdecimal() else part for part in re.split(r"(\d+)", path.name)]


def frame_files(folder: str | Path) -> list[Path]:
    """Image files of a folder in natural name order (frame2 before frame10); an error when
    there are none."""
    folder = Path(folder)
    if not folder.is_dir():
        raise InputError(f"--frames: {clip(str(folder))} is not a folder")
    files = sorted((p for p in folder.iterdir() if p.suffix.lower() in IMAGE_SUFFIXES), key=_natural_key)
    if not files:
        raise InputError(f"--frames: no images ({', '.join(IMAGE_SUFFIXES)}) in {folder}")
    return files


def iter_frames(video: str | None = None, frames: str | None = None) -> Iterator[np.ndarray]:
    """Yield BGR frames from a video file or an image folder (:func:`read_frame`'s checks for
    each file; :func:`video_frames`' for a video)."""
    if frames is not None:
        for i, path in enumerate(frame_files(frames), start=1):
            yield read_frame(path, f"frame {i}")
        return
    yield from video_frames(video)


# containers whose frame count is an index of the frames; elsewhere (MKV, WebM, ...) OpenCV
# estimates it from the duration, and a complete file may fall short of it
INDEXED_CONTAINERS = (".avi", ".mp4", ".m4v", ".mov")


def _stopped_short(video, frame: int, declared: int) -> None:
    """A video ends at ``frame`` of the ``declared``: an InputError for an indexed container (a
    truncated file, whose last frame read is partly lost and is not tracked), else a warning."""
    said = f"--video: {video} stops at frame {frame} of the {declared} its header declares"
    if Path(video).suffix.lower() in INDEXED_CONTAINERS:
        raise InputError(f"{said} (a truncated file?); frame {frame}, where its data ends, is not tracked")
    warnings.warn(f"{said}; the count of this container is an estimate, so frame {frame} is tracked as the last "
                  f"(if the file is truncated, that frame is partly lost)", RuntimeWarning, stacklevel=3)


def video_frames(video: str | os.PathLike) -> Iterator[np.ndarray]:
    """Yield a video's frames; an InputError before reading if its frames are larger than
    ``max_image_pixels()``, at the frame where it stops short of the frame count its header
    declares (:func:`_stopped_short`), and at a damaged frame of a Motion JPEG video
    (:class:`_JpegPackets`). Frames are read one ahead to know which is the last."""
    cap = _open_video(video)
    declared = cap.get(cv2.CAP_PROP_FRAME_COUNT)
    declared = int(declared) if 0 < declared < math.inf else 0  # 0 (or -1): the container does not say
    packets, count = None, 0
    try:
        packets = _JpegPackets.of(video, cap)
        ok, image = cap.read()
        while ok:
            ok, following = cap.read()
            if not ok and count + 1 < declared:
                _stopped_short(video, count + 1, declared)
            count += 1
            if packets is not None:
                packets.check(count)
            yield image
            image = following
    finally:
        cap.release()
        if packets is not None:
            packets.release()
    if count == 0:
        raise InputError(f"--video: {video} has no readable frames")


# OpenCV's names (CAP_PROP_FOURCC) of codecs whose frames are each a JPEG
JPEG_FOURCCS = ("MJPG", "JPEG", "AVRN", "AVDJ", "DMB1")


class _JpegPackets:
    """The coded frames of a Motion JPEG video, read beside the decoded ones by a second
    capture in OpenCV's raw mode (``CAP_PROP_FORMAT`` -1: the packet, not decoded), and checked
    as read_frame checks a JPEG file (:func:`~dcfkit.datasets.base.jpeg_damage`). FFmpeg's
    decoder conceals damage (it patches over the blocks it cannot decode) and OpenCV reports
    none. Each frame is one packet, so the two captures stay in step. The check is libjpeg's
    decode at 1/8 scale, about 40% more time than FFmpeg's full decode alone."""

    def __init__(self, video, raw: cv2.VideoCapture, first: bytes):
        self.video, self._raw, self._next = video, raw, first

    @classmethod
    def of(cls, video, cap: cv2.VideoCapture) -> _JpegPackets | None:
        """The packets of ``video`` if ``cap`` decodes it with FFmpeg from JPEG frames that
        libjpeg decodes (judged by the first one: a variant it does not read, lossless say, is
        not checked); else None."""
        fourcc = int(cap.get(cv2.CAP_PROP_FOURCC)).to_bytes(4, "little").decode("latin-1").upper()
        if cap.getBackendName() != "FFMPEG" or fourcc not in JPEG_FOURCCS:
            return None
        raw = cv2.VideoCapture(str(video), cv2.CAP_FFMPEG, [cv2.CAP_PROP_FORMAT, -1])
        try:
            ok, packet = raw.read() if raw.isOpened() and raw.get(cv2.CAP_PROP_FORMAT) == -1 else (False, None)
            first = packet.tobytes() if ok else b""
            if first.startswith(b"\xff\xd8") and jpeg_decodable(first):
                return cls(video, raw, first)
        except BaseException:  # the raw capture is not left to the garbage collector
            raw.release()
            raise
        raw.release()
        return None

    def check(self, frame: int) -> None:
        """InputError if the coded data of ``frame`` (1-based, the next one) is damaged."""
        data, self._next = self._next, None
        if data is None:
            ok, packet = self._raw.read()
            if not ok:  # no packet for a frame the decoder gave: the captures disagree, so no verdict
                return
            data = packet.tobytes()
        damage = jpeg_damage(data, decodable=True)
        if damage is not None:
            raise InputError(f"--video: {self.video}: frame {frame} is damaged (corrupt JPEG data: {damage}), so "
                             f"it is not tracked: FFmpeg would show it patched over")

    def release(self) -> None:
        self._raw.release()


def _open_video(video) -> cv2.VideoCapture:
    """An opened capture whose frame size is within ``max_image_pixels()``."""
    if not Path(video).is_file():
        raise InputError(f"--video: file not found: {clip(str(video))}")
    cap = cv2.VideoCapture(str(video))
    if not cap.isOpened():
        raise InputError(f"--video: OpenCV cannot open {video}")
    width, height = int(cap.get(cv2.CAP_PROP_FRAME_WIDTH)), int(cap.get(cv2.CAP_PROP_FRAME_HEIGHT))
    limit = max_image_pixels()
    if width * height > limit:
        cap.release()
        raise InputError(f"--video: {video} has {width}x{height} = {width * height:.3g} pixel frames, over the "
                         f"limit of {limit:.3g} (${IMAGE_PIXELS_VARIABLE})")
    return cap


def check_output_file(path: str | Path, what: str) -> Path:
    """Create the folder of the file ``path`` and check the file can be written there, before
    any work is done; ``what`` names the argument in the error."""
    path = Path(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"{what}: cannot create the folder {clip(str(path.parent))} ({exc.strerror})") from None
    if path.is_dir() or not os.access(path.parent, os.W_OK) or (path.exists() and not os.access(path, os.W_OK)):
        raise InputError(f"{what}: cannot write {clip(str(path))}")
    return path


# containers OpenCV's FFmpeg backend writes with the codecs below (.gif, .webm: no)
VIDEO_SUFFIXES = (".mp4", ".m4v", ".mov", ".mkv", ".avi")


class VideoWriter:
    """Writes frames with boxes drawn on them (.avi: MJPG, the other VIDEO_SUFFIXES: mp4v)."""

    def __init__(self, path: str | Path, fps: float = 10.0):
        if Path(path).suffix.lower() not in VIDEO_SUFFIXES:
            raise InputError(f"--save-video: cannot write a video named {shown(str(path))}: the name must end in "
                             f"{', '.join(VIDEO_SUFFIXES)}")
        self.path = check_output_file(path, "--save-video")
        self.fps = fps
        self._writer = None

    def write(self, frame: np.ndarray, boxes: dict[str, tuple] | None = None, text: str = "",
              points: dict[str, np.ndarray] | None = None) -> None:
        """Draw ``boxes`` (name -> x, y, w, h) with a legend, ``points`` (name -> (N, 2) x, y,
        e.g. repressed distractors, drawn as circles in that name's box colour) and ``text``."""
        if frame.ndim == 2:
            frame = cv2.cvtColor(frame, cv2.COLOR_GRAY2BGR)
        frame = frame.copy()
        for i, (name, box) in enumerate((boxes or {}).items()):
            if box is None or not np.all(np.isfinite(box)):
                continue
            x, y, w, h = (int(round(v)) for v in box)
            colour = COLOURS[i % len(COLOURS)]
            cv2.rectangle(frame, (x, y), (x + w - 1, y + h - 1), colour, 2)
            cv2.rectangle(frame, (6, 6 + 18 * i), (140, 24 + 18 * i), (0, 0, 0), -1)  # legend background
            cv2.putText(frame, name, (10, 20 + 18 * i), cv2.FONT_HERSHEY_SIMPLEX, 0.5, colour, 1, cv2.LINE_AA)
            for px, py in np.asarray((points or {}).get(name, np.zeros((0, 2)))).reshape(-1, 2):
                if np.isfinite(px) and np.isfinite(py):
                    cv2.circle(frame, (int(round(px)), int(round(py))), 3, colour, 1)
        if text:
            cv2.putText(frame, text, (10, frame.shape[0] - 10), cv2.FONT_HERSHEY_SIMPLEX, 0.5, (255, 255, 255), 1,
                        cv2.LINE_AA)
        if self._writer is None:
            fourcc = cv2.VideoWriter_fourcc(*("MJPG" if self.path.suffix.lower() == ".avi" else "mp4v"))
            self._writer = cv2.VideoWriter(str(self.path), fourcc, self.fps, (frame.shape[1], frame.shape[0]))
            if not self._writer.isOpened():
                raise InputError(f"cannot write video {self.path} (try a .avi or .mp4 name)")
        self._writer.write(frame)

    def close(self) -> None:
        if self._writer is not None:
            self._writer.release()
            self._writer = None
