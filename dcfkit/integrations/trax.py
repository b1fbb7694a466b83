"""dcfkit as a TraX server, the protocol through which the VOT toolkit runs trackers
(``vot-trax`` package, ``pip install "dcfkit[trax]"``; ``dcfkit trax CONFIG`` serves it).

The client starts the server process and talks to it over its stdin and stdout (or the
socket ``$TRAX_SOCKET`` names): ``stdout`` belongs to the protocol, so :func:`serve` sends
Python's prints to ``stderr``, where the log goes too. One session serves one object
(``initialize``, then ``frame`` after ``frame``); a new ``initialize`` starts a new tracker.

Regions: a TraX rectangle is ``left, top, width, height`` in 0-based pixels, dcfkit's own
in-memory convention, so boxes pass unchanged (vot-toolkit's dummy sequence pastes its target
at pixel ``(x, y)`` and annotates ``Rectangle(x, y, w, h)``; it rasterises a rectangle as the
pixels ``x .. x + w - 1``). A polygon (VOT's rotated boxes) initialises with its axis-aligned
bounding box, as vot-toolkit's ``Rectangle.convert`` makes it, and a mask with the box of its
pixels (libtrax's conversion); replies are rectangles.
Images: ``path`` (read by :func:`dcfkit.datasets.read_frame`, with its checks) and ``memory``
(``rgb`` or ``gray8``), on the ``color`` channel.

Each reply carries the object's properties ``confidence`` (the presence score of
:mod:`dcfkit.tracker.confidence`, the response's peak without a reliability component: VOT's
long-term analysis thresholds it), ``peak`` and ``apce``; a frame
without a response (the initialising frame, a frame held as blank) has neither.

An error on a frame (an unreadable image, a tracker failure) ends the session: the client is
sent ``quit`` with the message as its reason (``trax.reason``; ``trax.client.Client`` raises
``TraxException("Server terminated the session: <reason>")``), and the error is raised.
"""
from __future__ import annotations

import contextlib
import math
import sys
import unicodedata
from typing import Any, Iterator, Mapping

import numpy as np

from dcfkit import __version__
from dcfkit.datasets import read_frame
from dcfkit.errors import DcfkitError, InputError, MissingDependency
from dcfkit.integrations.trax_stream import ProtocolError, framed_connection
from dcfkit.experiments.loop import track
from dcfkit.tracker.confidence import confidence_of
from dcfkit.tracker.tracker import Tracker

try:
    import trax  # vot-trax: the optional dependency this module exists for
except ImportError as exc:
    raise MissingDependency('the TraX server needs the vot-trax package: pip install "dcfkit[trax]"') from exc

REGION_FORMATS = [trax.Region.RECTANGLE, trax.Region.POLYGON, trax.Region.MASK]
IMAGE_FORMATS = [trax.Image.PATH, trax.Image.MEMORY]
CHANNEL = trax.ImageChannel.COLOR


def serve(config: Mapping[str, Any]) -> None:
    """Serve TraX on stdin/stdout (or ``$TRAX_SOCKET``) until the client quits, one
    :class:`~dcfkit.tracker.tracker.Tracker` built from ``config`` (a resolved config,
    :func:`dcfkit.load_config`) per ``initialize``. An error on a frame is sent to the client
    as the reason of a ``quit``, then raised; a failed connection raises :class:`ProtocolError`."""
    with contextlib.redirect_stdout(sys.stderr):  # the protocol's messages are the only output on stdout
        Tracker(config)  # every check of the config, before the handshake: an error is said on stderr alone
        with framed_connection() as framing:
            link = _Link(framing)
            server = link.call(lambda: trax.Server(REGION_FORMATS, IMAGE_FORMATS, [CHANNEL], **_metadata(config)),
                               "cannot start the server")
            try:
                _session(server, link, config)
            except DcfkitError as exc:
                if not isinstance(exc, ProtocolError):
                    link.call(lambda: server.quit(reason=ascii_text(str(exc))), "cannot send quit")
                raise
            link.call(server.quit, "cannot send quit")


def _metadata(config: Mapping[str, Any]) -> dict:
    """What the handshake tells the client about the tracker."""
    return {"tracker_name": ascii_text(config["name"]), "tracker_family": "dcfkit",
            "tracker_description": ascii_text(config.get("description", "")),
            "metadata": {"dcfkit.version": __version__}}


def ascii_text(text: str) -> str:
    """``text`` in ASCII ('é' as 'e', 'θ' as 'theta', '²' as '2', '—' as '-', others '?'): libtrax
    reads a byte over 127 as the end of the stream (a signed ``char``), so one in the handshake
    or a quit's reason ends the session."""
    letters = (c for c in unicodedata.normalize("NFKD", text) if not unicodedata.combining(c))  # é: e + ´
    return "".join(c if c.isascii() else _ascii_name(c) for c in letters)


def _ascii_name(char: str) -> str:
    """A Greek letter by its name ('theta', 'Delta'), a dash as '-', anything else as '?'."""
    name = unicodedata.name(char, "")
    if name.startswith(("GREEK SMALL LETTER ", "GREEK CAPITAL LETTER ")):
        letter = name.rsplit(" ", 1)[1].lower()
        return letter.capitalize() if "CAPITAL" in name else letter
    return "-" if "DASH" in name or name == "MINUS SIGN" else "?"


class _Link:
    """Calls into libtrax, a failure said as a :class:`ProtocolError`: what failed, then why
    (the framing's words when it refused the client's stream, else libtrax's)."""

    def __init__(self, framing):
        self.framing = framing

    def call(self, call, failure: str):
        try:
            return call()
        except trax.TraxException as exc:
            if self.framing.error:
                raise ProtocolError(f"TraX: {self.framing.error}") from None
            raise ProtocolError(f"TraX: {failure} ({exc})") from None

    def wait(self, server):
        """The client's next request."""
        return self.call(server.wait, "no request from the client: it closed the connection without sending quit, "
                                      "or sent what the protocol does not allow")


def _session(server, link: _Link, config: Mapping[str, Any]) -> None:
    """Track each object the client initialises until it quits."""
    request = link.wait(server)
    while request.type != trax.TraxStatus.QUIT:
        if request.type != trax.TraxStatus.INITIALIZE:
            raise DcfkitError("TraX: the client sent a frame before initializing an object")
        run = _Run(server, link, request)
        track(Tracker(config), run.images(), run.box, on_frame=run.reply)
        request = run.next_request


class _Run:
    """One object, from its ``initialize`` to the next ``initialize`` or ``quit``: the frames as
    :func:`dcfkit.experiments.loop.track` reads them (numbered from 1, the initialising frame), and the
    replies it sends."""

    def __init__(self, server, link: _Link, request):
        self.server, self.link = server, link
        self.first = request
        if len(request.objects) != 1:  # libtrax joins consecutive initialize lines into one request
            raise ProtocolError(f"TraX: the client initialised {len(request.objects)} objects at once; the server "
                                f"tracks one (an initialize without arguments, then one with the region, then the "
                                f"frame, for each new object)")
        (region, _properties), = request.objects
        self.box = region_box(region)
        self.next_request = None

    def images(self) -> Iterator[np.ndarray]:
        request, frame = self.first, 1
        while True:
            yield read_image(request.image, f"frame {frame}")
            request, frame = self.link.wait(self.server), frame + 1
            if request.type != trax.TraxStatus.FRAME:
                self.next_request = request
                return

    def reply(self, index: int, image: np.ndarray, box: np.ndarray, tracker) -> None:
        region = trax.Rectangle.create(*(float(v) for v in box))
        self.link.call(lambda: self.server.status([(region, confidence_properties(tracker))]), "cannot reply")


def region_box(region) -> tuple[float, float, float, float]:
    """A TraX rectangle as ``(x, y, w, h)``; a polygon as its axis-aligned bounding box; a mask
    as the box of its set pixels."""
    if region.type == trax.Region.RECTANGLE:
        return tuple(float(v) for v in region.bounds())
    if region.type == trax.Region.POLYGON:
        points = np.array(list(region), dtype=np.float64)
        (left, top), (right, bottom) = points.min(axis=0), points.max(axis=0)
        return float(left), float(top), float(right - left), float(bottom - top)
    if region.type == trax.Region.MASK:
        rows, columns = np.nonzero(region.array())
        if rows.size == 0:
            raise InputError("frame 1: the TraX mask has no pixel set; dcfkit needs a target to track")
        x, y = region.offset()
        return (float(x + columns.min()), float(y + rows.min()),
                float(columns.max() - columns.min() + 1), float(rows.max() - rows.min() + 1))
    raise InputError(f"frame 1: a TraX {region.type} region (libtrax makes a special one of a region holding NaN, "
                     f"or of one number); dcfkit takes a rectangle, a polygon or a mask")


def read_image(images: Mapping[str, Any], what: str) -> np.ndarray:
    """The ``color`` image of a request as a BGR (or gray) uint8 array."""
    image = images.get(CHANNEL)
    if isinstance(image, trax.FileImage):
        return read_frame(image.path(), what)
    if isinstance(image, trax.MemoryImage):
        return memory_image(image.array(), what)
    kind = image.type() if image is not None else "no"
    raise InputError(f"{what}: a TraX {kind} image on the color channel; dcfkit reads path and memory images")


def memory_image(array: np.ndarray, what: str) -> np.ndarray:
    """A TraX memory image (``(H, W, 3)`` RGB or ``(H, W, 1)`` gray) as BGR or ``(H, W)`` gray uint8."""
    if array.dtype != np.uint8:
        raise InputError(f"{what}: a {array.dtype} memory image (gray16?); dcfkit tracks 8-bit images")
    return np.ascontiguousarray(array[:, :, ::-1]) if array.shape[2] == 3 else array[:, :, 0]


def confidence_properties(tracker) -> dict[str, float]:
    """``confidence`` (the presence score), ``peak`` and ``apce`` of the last frame; none on a
    frame without a response (:func:`dcfkit.tracker.confidence.confidence_of` gives NaN)."""
    peak, apce, score = confidence_of(tracker)
    return {"confidence": score, "peak": peak, "apce": apce} if math.isfinite(peak) else {}
