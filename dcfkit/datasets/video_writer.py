"""Writing a tracked video: frames with their boxes drawn, at the source's rate."""
from __future__ import annotations

import os
from pathlib import Path

import cv2
import numpy as np

from dcfkit.errors import InputError, clip, shown

COLOURS = ((0, 0, 255), (0, 255, 255), (255, 160, 0), (255, 0, 255), (255, 255, 255))  # BGR


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


DEFAULT_FPS = 10.0  # of an annotated video whose frames have no rate of their own


class VideoWriter:
    """Writes frames with boxes drawn on them (.avi: MJPG, the other VIDEO_SUFFIXES: mp4v) at
    ``fps``, which may be changed until the first frame is written."""

    def __init__(self, path: str | Path, fps: float = DEFAULT_FPS):
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
