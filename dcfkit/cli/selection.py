"""Drawing the first box on a frame in a window (``dcfkit track --select``). dcfkit's OpenCV is
the headless build, which has no windows (no ``cv2.selectROI``), so the window is matplotlib's
(TkAgg, QtAgg, ... whichever it finds, as ``plt.show()`` does)."""
from __future__ import annotations

import os
import sys
from typing import Callable

import numpy as np

from dcfkit.errors import InputError

INSTRUCTIONS = "drag a box around the target, then press Enter (Esc: cancel)"
NO_WINDOW = "pass the first box as --box x,y,w,h instead"
MAX_WINDOW = (1280, 800)  # pixels: a larger frame is shown scaled down


def check_display() -> None:
    """An InputError unless there is a display to open a window on (on Linux, ``$DISPLAY`` or
    ``$WAYLAND_DISPLAY``; elsewhere there always is)."""
    if sys.platform.startswith("linux") and not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        raise InputError(f"--select needs a display to draw the box on, and there is none ($DISPLAY and "
                         f"$WAYLAND_DISPLAY are not set): {NO_WINDOW}")


class BoxDrawing:
    """A rectangle to drag on ``image`` (BGR) drawn in the matplotlib figure ``fig``, which it
    fills; ``done()`` is called on Enter (accept) or Esc (cancel). :attr:`box` is the
    rectangle once accepted or when ``fig`` is closed with one drawn, None if cancelled or
    none was drawn."""

    def __init__(self, fig, image: np.ndarray, done: Callable[[], None]):
        from matplotlib.widgets import RectangleSelector  # lazy: matplotlib is slow to import

        self.height, self.width = image.shape[:2]
        ax = fig.add_axes((0, 0, 1, 1))
        ax.set_axis_off()
        rgb = image[..., ::-1] if image.ndim == 3 else image
        # data coordinates are pixel edges: pixel (i, j) covers [i, i + 1) x [j, j + 1), as dcfkit's boxes do
        ax.imshow(rgb, cmap="gray", extent=(0, self.width, self.height, 0), interpolation="nearest")
        self.selector = RectangleSelector(ax, lambda press, release: None, useblit=True, interactive=True,
                                          minspanx=2, minspany=2, spancoords="data",
                                          props={"edgecolor": "red", "fill": False, "linewidth": 1.5})
        self.cancelled = False
        self._done = done
        fig.canvas.mpl_connect("key_press_event", self._key)

    def _key(self, event) -> None:
        if event.key in ("enter", "escape"):
            self.cancelled = event.key == "escape"
            self._done()

    @property
    def box(self) -> tuple[float, float, float, float] | None:
        """``(x, y, w, h)``, 0-based whole pixels within the image."""
        x0, x1, y0, y1 = self.selector.extents
        x0, x1 = np.clip(np.round([x0, x1]), 0, self.width)
        y0, y1 = np.clip(np.round([y0, y1]), 0, self.height)
        if self.cancelled or x1 - x0 < 1 or y1 - y0 < 1:
            return None
        return float(x0), float(y0), float(x1 - x0), float(y1 - y0)


def select_box(image: np.ndarray) -> tuple[float, float, float, float]:
    """The box the user draws on ``image`` (BGR) in a window (:class:`BoxDrawing`); an
    InputError if there is no display or no matplotlib backend that opens windows, or if the
    window is closed without a box."""
    check_display()
    import matplotlib.pyplot as plt  # lazy: only --select opens windows

    height, width = image.shape[:2]
    scale = min(1.0, MAX_WINDOW[0] / width, MAX_WINDOW[1] / height)
    fig = plt.figure(figsize=(width * scale / 100, height * scale / 100), dpi=100)
    if fig.canvas.required_interactive_framework is None:  # Agg and the like draw into files only
        plt.close(fig)
        raise InputError(f"--select: matplotlib has no backend that opens windows here (it has "
                         f"{plt.get_backend()!r}; tkinter gives it one: on Debian or Ubuntu `apt install python3-tk`; "
                         f"or name one in $MPLBACKEND): {NO_WINDOW}")
    drawing = BoxDrawing(fig, image, done=lambda: plt.close(fig))
    fig.canvas.manager.set_window_title(f"dcfkit: {INSTRUCTIONS}")
    plt.show()  # until the window closes
    if drawing.box is None:
        raise InputError(f"--select: {'cancelled' if drawing.cancelled else 'no box was drawn'} ({INSTRUCTIONS}); "
                         f"or {NO_WINDOW}")
    return drawing.box
