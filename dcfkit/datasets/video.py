"""Reading frames (a video file, camera, stream or image folder) and writing annotated videos."""
from __future__ import annotations

import contextlib
import dataclasses
import itertools
import math
import queue
import re
import sys
import threading
import time
import warnings
from pathlib import Path
from typing import Iterator

import cv2
import numpy as np

from dcfkit.datasets import read_frame
from dcfkit.datasets.images import jpeg_damage, jpeg_decodable
from dcfkit.errors import InputError, InputWarning, clip
from dcfkit.limits import IMAGE_PIXELS_VARIABLE, max_image_pixels

IMAGE_SUFFIXES = (".jpg", ".jpeg", ".png", ".bmp", ".tif", ".tiff")


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


@dataclasses.dataclass
class FrameSource:
    """Frames to track, read one at a time as they are asked for, and what is known of them
    before the first: ``total`` (a video's declared frame count or a folder's images; None
    when the source does not say, as a camera or a live stream does not), ``fps`` (the rate it
    declares, None if none or an implausible one) and ``name`` (for messages). ``live``: a
    camera, a URL or a named pipe, whose frames come as they are made."""

    frames: Iterator[np.ndarray]
    name: str
    total: int | None = None
    fps: float | None = None
    live: bool = False


def open_source(video: str | None = None, frames: str | None = None) -> FrameSource:
    """``--frames``, a folder of images (:func:`read_frame`'s checks for each), or ``--video``:
    a camera index (``0``), a URL (``rtsp://``, ``http://``, ... as OpenCV's FFmpeg opens it),
    a video file, or a named pipe or device. A file is read as :func:`_capture_frames` says,
    its Motion JPEG frames checked for damage (:class:`_JpegPackets`); a live source without
    that check (it would read the frames a second time), in a thread (:func:`_read_in_thread`)."""
    if frames is not None:
        files = frame_files(frames)
        return FrameSource((read_frame(path, f"frame {i}") for i, path in enumerate(files, start=1)), str(frames),
                           total=len(files))
    if _is_camera(video):
        return _live_source(_open_camera(int(video)), video, camera=True)
    if URL.match(video):
        cap = _opened_in_thread(video, lambda: _quietly_opened(
            video, cv2.CAP_FFMPEG, [cv2.CAP_PROP_OPEN_TIMEOUT_MSEC, int(OPEN_TIMEOUT * 1000),
                                    cv2.CAP_PROP_READ_TIMEOUT_MSEC, int(READ_TIMEOUT * 1000)]))
        return _live_source(_checked(cap, video), video)
    path = Path(video)
    if not path.exists():
        raise InputError(f"--video: file not found: {clip(video)} (a camera is a number, 0 the first; a stream a URL)")
    if path.is_dir():
        raise InputError(f"--video: {clip(video)} is a folder: --frames reads a folder of images")
    if not path.is_file():  # a named pipe, or a device such as /dev/video0
        cap = _checked(_opened_in_thread(video, lambda: cv2.VideoCapture(video)), video)
        return _live_source(cap, video, camera=path.is_char_device())
    cap = _checked(cv2.VideoCapture(video), video)
    declared = _declared_count(cap)
    return FrameSource(_file_frames(cap, video, declared), _name(video), total=declared or None,
                       fps=_declared_fps(cap))


URL = re.compile(r"[A-Za-z][A-Za-z0-9+.-]*://")
# OpenCV's FFmpeg timeouts for a URL (its defaults, set so that a stall is recognised)
OPEN_TIMEOUT = READ_TIMEOUT = 30.0  # seconds
WATCHDOG_MARGIN = 5.0  # dcfkit's own wait beyond them, for what FFmpeg's timeouts do not cover (named pipes)
MAX_FPS = 1000.0  # a higher declared rate is a time base, not a frame rate


def _is_camera(video: str) -> bool:
    return video.isascii() and video.isdigit()


def _name(video: str) -> str:
    """``--video`` as messages name it: ``camera 0``, a URL with its user and password and the
    values of its query (``?token=...``) hidden, a file name; cut to a message's length."""
    if _is_camera(video):
        return f"camera {video}"
    if not URL.match(video):
        return clip(video)
    # the user info ends at the last '@' before the path, as FFmpeg splits it: a password may hold '@'
    hidden = re.sub(r"^([A-Za-z][A-Za-z0-9+.-]*://)[^/?#]*@", r"\1***@", video)
    return clip(re.sub(r"([?&;][^=&;#]*=)[^&;#]*", r"\1***", hidden))


def _quietly_opened(*args) -> cv2.VideoCapture:
    """``cv2.VideoCapture(*args)`` without OpenCV's warnings when it fails (one per backend
    tried): the error says it."""
    level = cv2.utils.logging.getLogLevel()
    cv2.utils.logging.setLogLevel(cv2.utils.logging.LOG_LEVEL_ERROR)
    try:
        return cv2.VideoCapture(*args)
    finally:
        cv2.utils.logging.setLogLevel(level)


def _opened_in_thread(video: str, open_capture) -> cv2.VideoCapture:
    """``open_capture()`` run in a thread, so that Ctrl-C or SIGTERM end the wait (OpenCV's
    open of a named pipe blocks until a program opens it for writing, and FFmpeg's of a URL
    until its timeout); a source not open within ``OPEN_TIMEOUT + WATCHDOG_MARGIN`` is an InputError."""
    seconds = OPEN_TIMEOUT + WATCHDOG_MARGIN
    with contextlib.closing(_in_thread((open_capture() for _ in range(1)), seconds, lambda count: (
            f"--video: {_name(video)} did not open within {seconds:g} s (a named pipe opens when a program "
            f"opens it for writing)"))) as opening:
        return next(opening)


def _open_camera(index: int) -> cv2.VideoCapture:
    cap = _quietly_opened(index)
    if not cap.isOpened():
        device = Path(f"/dev/video{index}")
        why = (f" ({device} exists: in use by another program, or no permission?)" if device.exists() else
               f" (there is no {device})" if sys.platform.startswith("linux") else "")
        raise InputError(f"--video: cannot open camera {index}{why}")
    return _checked(cap, str(index))


def _checked(cap: cv2.VideoCapture, video: str) -> cv2.VideoCapture:
    """``cap`` if it opened and its frame size is within ``max_image_pixels()``."""
    name = _name(video)
    if not cap.isOpened():
        raise InputError(f"--video: OpenCV cannot open {name}")
    width, height = int(cap.get(cv2.CAP_PROP_FRAME_WIDTH)), int(cap.get(cv2.CAP_PROP_FRAME_HEIGHT))
    limit = max_image_pixels()
    if width * height > limit:
        cap.release()
        raise InputError(f"--video: {name} has {width}x{height} = {width * height:.3g} pixel frames, over the "
                         f"limit of {limit:.3g} (${IMAGE_PIXELS_VARIABLE})")
    return cap


def _declared_count(cap: cv2.VideoCapture) -> int:
    """The frame count the container declares; 0 if it does not say (OpenCV gives 0 or -1)."""
    declared = cap.get(cv2.CAP_PROP_FRAME_COUNT)
    return int(declared) if 0 < declared < math.inf else 0


def _declared_fps(cap: cv2.VideoCapture) -> float | None:
    fps = cap.get(cv2.CAP_PROP_FPS)
    return fps if 0 < fps <= MAX_FPS else None  # NaN fails too


# containers whose frame count is an index of the frames; elsewhere (MKV, WebM, ...) OpenCV
# estimates it from the duration, and a complete file may fall short of it
INDEXED_CONTAINERS = (".avi", ".mp4", ".m4v", ".mov")


def _stopped_short(video: str, frame: int, declared: int) -> None:
    """A video ends at ``frame`` of the ``declared``: an InputError for a URL (a lost stream,
    whatever its name says) and a file of an indexed container (truncated), whose last frame
    read is partly lost and is not tracked; else a warning."""
    said = f"--video: {_name(video)} stops at frame {frame} of the {declared} its header declares"
    if URL.match(video) or Path(video).suffix.lower() in INDEXED_CONTAINERS:
        raise InputError(f"{said} (a truncated file or a lost stream?); frame {frame}, where its data ends, "
                         f"is not tracked")
    warnings.warn(f"{said}; the count of this container is an estimate, so frame {frame} is tracked as the last "
                  f"(if the file is truncated, that frame is partly lost)", InputWarning, stacklevel=3)


def _capture_frames(cap: cv2.VideoCapture, video: str, declared: int, packets: _JpegPackets | None = None):
    """Yield ``cap``'s frames, then release it; an InputError at the frame where it stops short
    of the count its header ``declared`` (:func:`_stopped_short`; frames are then read one
    ahead, to know which is the last: without a count, each is given as soon as it is read),
    and at a damaged frame (``packets``)."""
    count = 0
    try:
        ok, image = cap.read()
        while ok:
            count += 1
            if declared:
                ok, following = cap.read()
                if not ok and count < declared:
                    _stopped_short(video, count, declared)
            if packets is not None:
                packets.check(count)
            yield image
            ok, image = (ok, following) if declared else cap.read()
    finally:
        cap.release()
        if packets is not None:
            packets.release()


def _file_frames(cap: cv2.VideoCapture, video: str, declared: int) -> Iterator[np.ndarray]:
    """A video file's frames (:func:`_capture_frames`), those of a Motion JPEG video checked
    (:class:`_JpegPackets`); an InputError if it has none."""
    count = 0
    try:
        packets = _JpegPackets.of(video, cap)
    except BaseException:
        cap.release()
        raise
    for count, image in enumerate(_capture_frames(cap, video, declared, packets), start=1):
        yield image
    if count == 0:
        raise InputError(f"--video: {clip(video)} has no readable frames")


def _live_source(cap: cv2.VideoCapture, video: str, camera: bool = False) -> FrameSource:
    declared = 0 if camera else _declared_count(cap)
    return FrameSource(_read_in_thread(_live_frames(cap, video, declared, camera), _name(video)), _name(video),
                       total=declared or None, fps=_declared_fps(cap), live=True)


def _live_frames(cap: cv2.VideoCapture, video: str, declared: int, camera: bool) -> Iterator[np.ndarray]:
    """The frames of a camera, URL or pipe (:func:`_capture_frames`) as they come. Where they
    end without a declared count: an InputError for a camera (it has no end), and for a
    stream that gave no frame for ``READ_TIMEOUT`` (a stall, which OpenCV's FFmpeg reports
    as an end); else the stream ended (OpenCV does not tell its end from a lost connection)."""
    name, count, asked = _name(video), 0, time.monotonic()
    for count, image in enumerate(_capture_frames(cap, video, declared), start=1):
        yield image
        asked = time.monotonic()
    if camera:
        raise InputError(f"--video: {name} stopped giving frames after frame {count} (unplugged, or taken by "
                         f"another program?)" if count else f"--video: {name} gave no frame")
    if not declared and time.monotonic() - asked >= 0.9 * READ_TIMEOUT:
        raise InputError(f"--video: {name} gave no frame for {READ_TIMEOUT:g} s after frame {count}: the stream "
                         f"stalled")
    if count == 0:
        raise InputError(f"--video: {name} has no readable frames")


_END = object()


def _read_in_thread(items: Iterator, name: str) -> Iterator:
    """The frames ``items`` of a live source, read in a thread (:func:`_in_thread`), so that a
    run waiting for a frame ends at once on Ctrl-C or SIGTERM (OpenCV's read of a stalled
    stream returns only at its timeout, of a stalled named pipe never); no frame for
    ``READ_TIMEOUT + WATCHDOG_MARGIN`` is an InputError naming ``name``."""
    seconds = READ_TIMEOUT + WATCHDOG_MARGIN
    return _in_thread(items, seconds, lambda count: f"--video: {name} gave no frame for {seconds:g} s after frame "
                                                    f"{count}: the stream stalled")


def _in_thread(items: Iterator, seconds: float, stalled) -> Iterator:
    """Yield ``items``, read in a thread at most one ahead. An exception of ``items`` is raised
    here, in its place, and no item for ``seconds`` is an InputError saying ``stalled(count)``
    (``count``: the items yielded); when the caller stops, the thread stops after its current
    read and closes ``items``."""
    queue_, stop = queue.Queue(maxsize=1), threading.Event()
    threading.Thread(target=_read_into, args=(items, queue_, stop), name="dcfkit-read", daemon=True).start()
    try:
        for count in itertools.count():
            try:
                item, exc = queue_.get(timeout=seconds)
            except queue.Empty:
                raise InputError(stalled(count)) from None
            if exc is not None:
                raise exc
            if item is _END:
                return
            yield item
    finally:
        stop.set()


def _read_into(items: Iterator, queue_: queue.Queue, stop: threading.Event) -> None:
    """The reading thread of :func:`_in_thread`: ``(item, None)`` for each item, then
    ``(_END, None)`` or ``(None, exception)``, until ``stop`` is set; then ``items`` is closed."""
    def put(entry) -> bool:
        while not stop.is_set():
            try:
                queue_.put(entry, timeout=0.1)
                return True
            except queue.Full:
                pass
        return False

    try:
        for item in items:
            if not put((item, None)):
                return
        put((_END, None))
    except BaseException as exc:  # noqa: BLE001 - handed to the caller, raised there
        put((None, exc))
    finally:
        items.close()


# OpenCV's names (CAP_PROP_FOURCC) of codecs whose frames are each a JPEG
JPEG_FOURCCS = ("MJPG", "JPEG", "AVRN", "AVDJ", "DMB1")


class _JpegPackets:
    """The coded frames of a Motion JPEG video, read beside the decoded ones by a second
    capture in OpenCV's raw mode (``CAP_PROP_FORMAT`` -1: the packet, not decoded), and checked
    as read_frame checks a JPEG file (:func:`~dcfkit.datasets.images.jpeg_damage`). FFmpeg's
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


