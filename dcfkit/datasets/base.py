"""What every benchmark layout shares: :class:`Sequence`, :class:`DatasetError`, the readers of
frames, boxes and attribute flags, and the helpers a loader is built from (frame lists,
sequence selection). A layout module (or a plugin's) needs nothing else from dcfkit."""
from __future__ import annotations

import dataclasses
import difflib
import io
import logging
import math
import os
import re
import stat
import struct
import warnings
import zlib
from pathlib import Path
from typing import Iterable, Mapping

import numpy as np

from dcfkit.errors import DcfkitError, InputWarning, clip, shown
from dcfkit.limits import IMAGE_PIXELS_VARIABLE, max_image_pixels

log = logging.getLogger(__name__)


class DatasetError(DcfkitError, ValueError):
    """A benchmark folder, annotation file or sequence name is wrong (the message says where)."""


#: Long names of the attribute abbreviations of UAV123 (first, in the column order of its att
#: files), OTB and LaSOT; each layout module keeps its benchmark's column order.
ATTRIBUTE_NAMES = {
    "SV": "Scale Variation",
    "ARC": "Aspect Ratio Change",
    "LR": "Low Resolution",
    "FM": "Fast Motion",
    "FOC": "Full Occlusion",
    "POC": "Partial Occlusion",
    "OV": "Out-of-View",
    "BC": "Background Clutter",
    "IV": "Illumination Variation",
    "VC": "Viewpoint Change",
    "CM": "Camera Motion",
    "SOB": "Similar Object",
    "OCC": "Occlusion",
    "DEF": "Deformation",
    "MB": "Motion Blur",
    "IPR": "In-Plane Rotation",
    "OPR": "Out-of-Plane Rotation",
    "ROT": "Rotation",
}


# --------------------------------------------------------------------------- Sequence


@dataclasses.dataclass(frozen=True, eq=False)
class Sequence:
    """One benchmark sequence.

    ``frames`` holds the image paths in order; ``ground_truth`` is ``(N, 4) float64``,
    0-based ``(x, y, w, h)``, read-only, with NaN rows kept for out-of-view frames.
    ``attributes`` maps an attribute abbreviation (e.g. ``"SV"``) to whether the sequence
    has it; it is empty when the benchmark provides none. ``annotation`` is the file the
    ground truth was read from (None for sequences made in code). ``ground_truth_withheld``
    is True for a test split that publishes frame 1's box only (GOT-10k, TrackingNet): rows
    2..N are NaN, so the sequence can be tracked but not scored (:func:`scored_sequences`).
    """

    name: str
    frames: tuple[Path, ...]
    ground_truth: np.ndarray
    attributes: Mapping[str, bool] = dataclasses.field(default_factory=dict)
    dataset: str = ""
    annotation: Path | None = None
    ground_truth_withheld: bool = False

    def __post_init__(self):
        gt = np.array(self.ground_truth, dtype=np.float64, copy=True).reshape(-1, 4)
        if len(gt) != len(self.frames):
            raise DatasetError(
                f"sequence {self.name!r}: {len(self.frames)} frames but {len(gt)} boxes")
        if not self.frames:
            raise DatasetError(f"sequence {self.name!r} has no frames"
                               + (f" ({self.annotation} holds no box)" if self.annotation else ""))
        gt.setflags(write=False)
        object.__setattr__(self, "ground_truth", gt)
        object.__setattr__(self, "frames", tuple(Path(f) for f in self.frames))
        object.__setattr__(self, "attributes", dict(self.attributes))

    def __len__(self) -> int:
        return len(self.frames)

    def __repr__(self) -> str:
        flags = ",".join(k for k, v in self.attributes.items() if v)
        withheld = ", ground truth withheld" if self.ground_truth_withheld else ""
        return f"Sequence({self.dataset}/{self.name}, {len(self)} frames{withheld}{', ' + flags if flags else ''})"

    @property
    def init_box(self) -> np.ndarray:
        """Frame 1's ground-truth box, ``(4,) float64`` 0-based (may contain NaN)."""
        return self.ground_truth[0].copy()

    def frame(self, i: int) -> np.ndarray:
        """Frame ``i`` (0-based index) as ``(H, W, 3) uint8`` BGR; a :class:`DatasetError` if
        unreadable, which numbers the frame from 1 as the benchmarks' files do."""
        return read_frame(self.frames[i], f"frame {i + 1} of sequence {self.name!r}")


# --------------------------------------------------------------------------- images


def _regular_file_bytes(path, name: str, limit: int, over: str) -> bytes:
    """The bytes of ``path``: a regular file (a FIFO would block, /dev/zero never end) of at
    most ``limit`` bytes, else a :class:`DatasetError` ``cannot read <name> (...)`` (``over``
    ends the one of a file too large); an OSError of the file system passes."""
    info = os.stat(path)
    if not stat.S_ISREG(info.st_mode):
        raise DatasetError(f"cannot read {name} (not a regular file)")
    if info.st_size > limit:
        raise DatasetError(f"cannot read {name} ({info.st_size:.3g} bytes{over})")
    with open(path, "rb") as file:
        return file.read(info.st_size + 1)  # a file growing meanwhile is cut: its size was checked


def _read_image_bytes(path, what: str) -> bytes:
    """The bytes of an image file: a regular file no larger than an uncompressed image of the
    pixel limit could be."""
    try:
        return _regular_file_bytes(path, f"{what}: {path}", 6 * max_image_pixels() + 2**20,  # 16-bit BGR, headers
                                   f", more than an image of the limit of {max_image_pixels():.3g} pixels can take: "
                                   f"${IMAGE_PIXELS_VARIABLE}")
    except OSError as exc:
        reason = "file does not exist" if not os.path.exists(path) else exc.strerror
        raise DatasetError(f"cannot read {what}: {path} ({reason})") from None


def read_frame(path: str | os.PathLike, what: str = "frame") -> np.ndarray:
    """A BGR image; :class:`DatasetError` naming the file when it is missing, not an image, larger
    than :func:`~dcfkit.limits.max_image_pixels` (read from its header, before decoding), a
    truncated JPEG (``cv2.imread`` would return one grey below the cut, with a warning only), a
    JPEG whose data libjpeg reports corrupt (``cv2.imread`` would return it with a warning, part
    of it grey or wrong), or a TIFF whose data libtiff cannot decode (likewise). A JPEG that
    lacks just its end-of-image marker, or has zero bytes before it, common defects, is read as
    imread would. Decoding is OpenCV's, unchanged: a 16-bit image keeps its high byte, with a
    warning when that leaves fewer than 64 grey levels (12-bit data in a 16-bit PNG keeps 16)."""
    import cv2  # deferred: listing sequences needs no OpenCV

    data = _read_image_bytes(path, what)
    _check_size(data, path, what)
    if data.startswith(_TIFF_SIGNATURES):
        _check_tiff_data(data, path, what)
    image = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_COLOR | cv2.IMREAD_ANYDEPTH)
    if image is not None and image.dtype != np.uint8:
        _warn_if_few_levels(image, path)
        image = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_COLOR)  # OpenCV's own 8-bit conversion
    if image is None and _missing_end_marker(data):
        data += _JPEG_END
        image = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_COLOR)
        if image is not None and (image[-8:, -8:] == 128).all():  # libjpeg's fill for missing data
            raise DatasetError(f"cannot read {what}: {path} (truncated JPEG: the image data stops "
                               f"before its end)")
    if image is None:
        raise DatasetError(f"cannot read {what}: {path} (not a readable image)")
    if data.startswith(b"\xff\xd8"):
        _check_jpeg_data(data, path, what)
    return image


_FEW_LEVELS_WARNED: set[str] = set()


def _warn_if_few_levels(image: np.ndarray, path) -> None:
    """Warn when a 16-bit image read as 8 bits (its high byte) keeps fewer than 64 grey levels."""
    folder = str(Path(path).parent)
    if image.dtype == np.uint16 and int(image.max()) >> 8 < 64 and folder not in _FEW_LEVELS_WARNED:
        _FEW_LEVELS_WARNED.add(folder)  # once a folder: warnings' own once-only is reset whenever a filter changes
        warnings.warn(f"{folder}: 16-bit frames whose values stay below {64 << 8} keep fewer than 64 "
                      f"grey levels read as 8 bits (12-bit data keeps 16); convert them to 8 bits, scaled to "
                      f"their range, to track them", DatasetWarning, stacklevel=3)


class DatasetWarning(InputWarning):
    """A benchmark file dcfkit reads, but maybe not as its author meant."""


def _check_size(data: bytes, path, what: str) -> None:
    """DatasetError unless the image header declares at most ``max_image_pixels()`` pixels: a
    small file can declare billions (a 876 KB PNG of 30000x30000 decodes to 2.7 GB). Pillow reads
    the header only (JPEG, PNG, BMP, TIFF, WebP and more); a file whose header it cannot read is
    refused, as its size is unknown, unless it is a PNG with an intact IHDR (:func:`_png_size`)."""
    from PIL import Image  # deferred, as OpenCV: listing sequences reads no image

    limit = max_image_pixels()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", Image.DecompressionBombWarning)  # dcfkit's limit is the one that applies
        try:
            with Image.open(io.BytesIO(data)) as header:
                width, height = header.size
        except Image.DecompressionBombError:  # Pillow's own limit, which it checks first: its size is not said
            raise DatasetError(f"cannot read {what}: {path} (its header declares more pixels than Pillow reads: "
                               f"{2 * Image.MAX_IMAGE_PIXELS:.3g}, twice PIL.Image.MAX_IMAGE_PIXELS)") from None
        except Exception:  # Pillow's plugins raise several types for a header they cannot read
            size = _png_size(data)
            if size is None:
                raise DatasetError(f"cannot read {what}: {path} (not a readable image)") from None
            width, height = size
    if width * height > limit:
        raise DatasetError(f"cannot read {what}: {path} (its header declares {width}x{height} = "
                           f"{width * height:.3g} pixels, over the limit of {limit:.3g}: ${IMAGE_PIXELS_VARIABLE})")


_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def _png_size(data: bytes) -> tuple[int, int] | None:
    """Width and height from a PNG's IHDR chunk, if it is intact; else None. Pillow reads the
    chunks up to the image data and refuses a bad CRC in any, while libpng (OpenCV's decoder)
    only warns about one in an ancillary chunk (tEXt, say) and decodes the image; it refuses
    damage to the critical ones (IHDR, IDAT), so ``cv2.imdecode`` returns None for those."""
    if not data.startswith(_PNG_SIGNATURE) or len(data) < 33:
        return None
    length, kind, width, height = struct.unpack(">I4sII", data[8:24])
    if length != 13 or kind != b"IHDR" or zlib.crc32(data[12:29]) != int.from_bytes(data[29:33], "big"):
        return None
    return width, height


_TIFF_SIGNATURES = (b"II*\0", b"MM\0*", b"II+\0", b"MM\0+")  # TIFF and BigTIFF, either byte order
# Pillow's names of the TIFF compressions whose data any bytes are: nothing for a decode to find
_TIFF_UNCHECKABLE = ("raw", "packbits")
_TIFF_DAMAGE = ("decoder error", "image file is truncated")  # how Pillow's decoders say the data is broken


def _check_tiff_data(data: bytes, path, what: str) -> None:
    """DatasetError if libtiff cannot decode a compressed TIFF's image data (a broken LZW or
    Deflate stream). OpenCV's decoder (its own libtiff) prints the error and returns the image,
    wrong or blank from the damage on; Pillow's raises. So Pillow decodes it too, first (the two
    images are not held at once): twice the decoding time, for compressed TIFF frames only,
    which no benchmark uses. Pillow's other failures (a layout it does not read) say nothing
    about damage and leave the file to OpenCV."""
    from PIL import Image  # deferred, as OpenCV

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # metadata warnings: the header was checked, the verdict is the decode's
        try:
            with Image.open(io.BytesIO(data)) as image:
                compression = image.info.get("compression", "unknown")
                if compression not in _TIFF_UNCHECKABLE:
                    image.load()
        except Exception as exc:  # as in _check_size, several types
            if str(exc).startswith(_TIFF_DAMAGE):
                raise DatasetError(f"cannot read {what}: {path} (corrupt TIFF data: libtiff cannot decode its "
                                   f"{compression} data)") from None


def _check_jpeg_data(data: bytes, path, what: str) -> None:
    """DatasetError if libjpeg reports the JPEG's data corrupt (:func:`jpeg_damage`)."""
    damage = jpeg_damage(data)
    if damage is not None:
        raise DatasetError(f"cannot read {what}: {path} (corrupt JPEG data: {damage})")


def jpeg_damage(data: bytes, decodable: bool = False) -> str | None:
    """What libjpeg reports wrong with a JPEG's data, or None. OpenCV's decoder only prints
    such a warning and returns the image, grey or garbled from the damage on; simplejpeg (the
    same libjpeg-turbo) raises instead. Its decode at 1/8 scale reads every coded coefficient,
    so it sees the same errors, at a third of a full decode's time. None too for a JPEG
    simplejpeg cannot decode at all (CMYK, say), which has nothing to say about corruption,
    unless it is known to be ``decodable`` (a video frame, whose first frame libjpeg decoded);
    and for one with zero padding before its end-of-image marker (:func:`_without_zero_padding`)."""
    complaint = _libjpeg_complaint(data)
    if complaint is None or (not decodable and not jpeg_decodable(data)):
        return None
    unpadded = _without_zero_padding(data, complaint)
    if unpadded is not None and _libjpeg_complaint(unpadded) is None:
        return None
    return complaint


def jpeg_decodable(data: bytes) -> bool:
    """Whether libjpeg (simplejpeg's) decodes ``data``, warnings or not."""
    return _libjpeg_complaint(data, strict=False) is None


def _libjpeg_complaint(data: bytes, strict: bool = True) -> str | None:
    """libjpeg's first warning (``strict``) or error decoding ``data`` at 1/8 scale, or None."""
    import simplejpeg  # deferred, as OpenCV

    try:
        simplejpeg.decode_jpeg(data, colorspace="BGR", min_height=1, min_width=1, strict=strict)
    except ValueError as exc:
        return str(exc)
    return None


# libjpeg's JWRN_EXTRANEOUS_DATA for the end-of-image marker (its wording since libjpeg 6)
_EXTRANEOUS_BEFORE_END = re.compile(r"\d+ extraneous bytes before marker 0xd9")


def _without_zero_padding(data: bytes, complaint: str) -> bytes | None:
    """``data`` without the zero bytes just before its end-of-image marker, if libjpeg's
    ``complaint`` is about bytes there: padding some writers add. The caller checks that the
    rest decodes cleanly, all its blocks from its own data; then the padding was never read
    and OpenCV's decode is the same with it. Other bytes there are refused: damage that makes
    the decoder reach the last block early leaves coded data there and gets the same warning
    (47% of JPEGs with 1 to 5 random bytes of coded data changed did), and damage that makes
    it run past the end reads the padding as data."""
    end = data.find(_JPEG_END, data.rfind(b"\xff\xda"))  # markers cannot occur in coded data
    if not _EXTRANEOUS_BEFORE_END.search(complaint) or end < 0:
        return None
    start = len(data[:end].rstrip(b"\0"))
    return data[:start] + data[end:] if start < end else None


_JPEG_END = b"\xff\xd9"


def _missing_end_marker(data: bytes) -> bool:
    """A JPEG whose last scan (SOS marker) has no end-of-image marker after it (markers cannot
    occur inside entropy-coded data, where 0xFF is stuffed)."""
    return data.startswith(b"\xff\xd8") and data.rfind(b"\xff\xd9") < data.rfind(b"\xff\xda")


# --------------------------------------------------------------------------- annotation files

_SEPARATORS = re.compile(r"[,\s]+")
MAX_TEXT_BYTES = 64 * 2**20  # an annotation file: LaSOT's longest is under 1 MB, a VOT mask file tens of MB
MAX_LINE_CHARS = 4096  # a line of boxes or flags (a VOT mask line is read by its own layout)
# a number as the toolkits write one (and libtrax's atof reads): ASCII digits only (float() also
# takes '٣' and '2_0'); compile it with re.IGNORECASE and re.ASCII
NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?|[-+]?(?:nan|inf|infinity)"
_NUMBER = re.compile(NUMBER, re.IGNORECASE | re.ASCII)


def read_text(path: Path) -> str:
    """A benchmark text file (UTF-8, optional BOM): a regular file (a FIFO would block,
    /dev/zero never end) of at most :data:`MAX_TEXT_BYTES`; :class:`DatasetError` naming it
    otherwise."""
    try:
        data = _regular_file_bytes(path, str(path), MAX_TEXT_BYTES,
                                   f": an annotation file of more than {MAX_TEXT_BYTES:.3g} bytes is not one")
        return data.decode("utf-8-sig")
    except FileNotFoundError:
        raise DatasetError(f"annotation file not found: {path}") from None
    except UnicodeDecodeError as exc:
        raise DatasetError(f"{path}: not a text annotation file (byte {exc.start} is not UTF-8)") from None
    except OSError as exc:
        raise DatasetError(f"cannot read {path}: {exc.strerror}") from None


def listed(annotation: Path) -> bool:
    """Whether a sequence's annotation file is there (a folder of a benchmark lists the
    sequence): whatever it is, a FIFO or a link to /dev/zero too, so that reading it says what
    is wrong instead of the sequence vanishing from the list."""
    return os.path.lexists(annotation)


def parse_number(field: str) -> float:
    """A number of an annotation file (ASCII digits, ``nan`` and ``inf`` as written); ValueError
    for anything else Python's ``float`` would take."""
    if not _NUMBER.fullmatch(field):
        raise ValueError(f"could not convert {field[:40]!r} to a number")
    value = float(field)
    if math.isinf(value) and "inf" not in field.lower():
        raise ValueError(f"{field[:40]!r} is beyond the range of a float")
    return value


def annotation_lines(text: str) -> list[str]:
    """The lines of an annotation file, broken at line feeds alone (``str.splitlines`` also
    breaks at form feeds and U+2028, and messages would name the wrong line)."""
    return [line.removesuffix("\r") for line in text.split("\n")]


def _fields(line: str, path: Path, n: int) -> list[str]:
    """The values of line ``n`` (0-based) of ``path``; a line too long to be one is refused
    before it is split."""
    if len(line) > MAX_LINE_CHARS:
        raise DatasetError(f"{path}, line {n + 1}: {len(line)} characters, too long for a line of boxes or flags "
                           f"(at most {MAX_LINE_CHARS})")
    return [f for f in _SEPARATORS.split(line.strip()) if f]


def read_boxes(path: str | os.PathLike, one_based: bool = True) -> np.ndarray:
    """Read one ``x,y,w,h`` box per line (commas, tabs or spaces) as ``(N, 4) float64``.

    With ``one_based`` (the benchmark convention), 1 is subtracted from x and y so the
    result is 0-based. ``NaN`` values are kept. Trailing blank lines are ignored; a blank
    or malformed line inside the file is a :class:`DatasetError` naming file and line.
    """
    path = Path(path)
    text = read_text(path).rstrip()
    lines = annotation_lines(text) if text else []
    boxes = np.empty((len(lines), 4), dtype=np.float64)
    for n, line in enumerate(lines):
        fields = _fields(line, path, n)
        try:
            if len(fields) != 4:
                raise ValueError
            boxes[n] = [parse_number(f) for f in fields]
        except ValueError:
            raise DatasetError(
                f"{path}, line {n + 1}: expected 4 numbers 'x,y,w,h' separated by commas, "
                f"tabs or spaces, got {shown(line.strip())}") from None
    if one_based:
        boxes[:, :2] -= 1.0
    return boxes


_FIELD = re.compile(r"[^,\s]+")
MAX_FRAME_VALUE = 2**31 - 1  # flags and cover levels are small; a larger value is no flag


def read_frame_values(path: Path, n_frames: int) -> np.ndarray:
    """One whole number per frame, separated by commas, spaces or new lines (LaSOT's
    ``full_occlusion.txt`` holds one line, GOT-10k's ``.label`` files one value a line), as
    ``(n_frames,) int64``; :class:`DatasetError` naming the file and the line of a value that is
    not a whole number, or the count when it is not ``n_frames``."""
    values = []
    for n, line in enumerate(annotation_lines(read_text(path))):
        for match in _FIELD.finditer(line):  # one at a time: LaSOT's single line may be long
            field = match.group()
            try:
                value = parse_number(field)
                if not value.is_integer() or abs(value) > MAX_FRAME_VALUE:
                    raise ValueError
            except ValueError:
                raise DatasetError(f"{path}, line {n + 1}: expected whole numbers, one per frame, got {shown(field)} "
                                   f"for frame {len(values) + 1}") from None
            values.append(int(value))
            if len(values) > n_frames:
                raise DatasetError(f"{path}: more values than its {n_frames} frames; one value per frame is required")
    if len(values) != n_frames:
        raise DatasetError(f"{path}: {len(values)} values for {n_frames} frames; one value per frame is required")
    return np.array(values, dtype=np.int64)


def read_flags(path: Path, names: tuple[str, ...]) -> dict[str, bool]:
    """One line of 0/1 flags, one per name in ``names`` (e.g. a UAV123 att file)."""
    fields = _fields(read_text(path).strip(), path, 0)
    if len(fields) != len(names) or any(f not in ("0", "1") for f in fields):
        raise DatasetError(
            f"{path}, line 1: expected {len(names)} 0/1 flags ({' '.join(names)}), "
            f"got {shown(' '.join(fields))}")
    return {name: f == "1" for name, f in zip(names, fields)}


# --------------------------------------------------------------------------- frame lists


def numbered_frames(folder: Path, pattern: str, first: int, last: int, what: str) -> tuple[Path, ...]:
    """Paths ``folder / (pattern % k)`` for k in first..last; all must exist."""
    if not folder.is_dir():
        raise DatasetError(f"{what}: image folder not found: {folder}")
    present = set(os.listdir(folder))
    names = [pattern % k for k in range(first, last + 1)]
    missing = [n for n in names if n not in present]
    if missing:
        listed = ", ".join(missing[:3]) + (f" and {len(missing) - 3} more" if len(missing) > 3 else "")
        raise DatasetError(
            f"{what}: {len(missing)} of frames {pattern % first}..{pattern % last} missing "
            f"in {folder}: {listed}")
    return tuple(folder / n for n in names)


def annotated_frames(folder: Path, pattern: str, boxes: np.ndarray, anno: Path, what: str,
                     first: int = 1) -> tuple[Path, ...]:
    """Frames ``first``.. of a folder holding exactly the N annotated ``.jpg`` frames; the error
    names either the missing frames or, when the images simply run out, the annotation's length."""
    n_jpgs = count_jpgs(folder, what)
    counted = f"{n_jpgs} .jpg files in {folder}"
    last = first + len(boxes) - 1
    if n_jpgs < len(boxes) and all((folder / (pattern % k)).is_file() for k in range(first, first + n_jpgs)):
        raise DatasetError(f"{anno}: {len(boxes)} annotation lines but {counted}: either the annotation has "
                           f"extra lines or frames {pattern % (first + n_jpgs)}..{pattern % last} are missing")
    frames = numbered_frames(folder, pattern, first, last, what)
    check_box_count(boxes, n_jpgs, anno, counted)  # extra images
    return frames


def count_jpgs(folder: Path, what: str) -> int:
    """How many ``.jpg`` files ``folder`` holds; :class:`DatasetError` if it is not a folder."""
    if not folder.is_dir():
        raise DatasetError(f"{what}: image folder not found: {folder}")
    return sum(1 for f in os.listdir(folder) if f.lower().endswith(".jpg"))


def held_out_sequence(name: str, folder: Path, pattern: str, first: int, anno: Path, dataset: str, what: str,
                      one_based: bool = True) -> Sequence:
    """A sequence of a test split: every ``.jpg`` of ``folder`` (``pattern`` numbered from
    ``first``), tracked whole, and the annotation ``anno``, which holds one box per frame or, as
    published, frame 1's only: then rows 2..N are NaN and ``ground_truth_withheld`` is set."""
    n_frames = count_jpgs(folder, what)
    frames = numbered_frames(folder, pattern, first, first + n_frames - 1, what)
    boxes = read_boxes(anno, one_based=one_based)
    withheld = len(boxes) == 1 and n_frames > 1
    if withheld:
        boxes = np.vstack([boxes, np.full((n_frames - 1, 4), np.nan)])
    else:
        check_box_count(boxes, n_frames, anno, f"{n_frames} .jpg files in {folder}; a test split's annotation may "
                                               f"also hold frame 1's box only")
    return Sequence(name, frames, boxes, {}, dataset, anno, ground_truth_withheld=withheld)


def check_box_count(boxes: np.ndarray, n_frames: int, anno: Path, frames_desc: str) -> None:
    """:class:`DatasetError` naming ``anno`` unless it has one box per frame."""
    if len(boxes) != n_frames:
        raise DatasetError(
            f"{anno}: {len(boxes)} annotation lines but {n_frames} frames ({frames_desc}); "
            f"one line per frame is required")


# --------------------------------------------------------------------------- roots and selection


def scored_sequences(sequences: Iterable[Sequence]) -> list[Sequence]:
    """The sequences whose ground truth can score a tracker: all but those whose ground truth the
    benchmark withholds after frame 1 (``ground_truth_withheld``), which are left out with a
    warning; a :class:`DatasetError` saying so when none is left (a test split, whose results
    are scored by the benchmark's server), never scores computed against NaN rows."""
    sequences = list(sequences)
    scored = [s for s in sequences if not s.ground_truth_withheld]
    withheld = [s.name for s in sequences if s.ground_truth_withheld]
    if withheld and not scored:
        dataset = sequences[0].dataset or "this dataset"
        raise DatasetError(
            f"no scores: {dataset} publishes the ground truth of frame 1 only for these {len(withheld)} sequences "
            f"(a test split: {', '.join(withheld[:5])}{' ...' if len(withheld) > 5 else ''}). Submit the result "
            f"files OUT/<tracker>/<sequence>.txt to the benchmark's evaluation server (docs/evaluation.md, "
            f"'Test splits')")
    if withheld:
        log.warning("%d of %d sequences left out of the scores: their ground truth is withheld after frame 1 "
                    "(a test split): %s", len(withheld), len(sequences), ", ".join(withheld[:10]))
    return scored


def require_root(root, what: str) -> Path:
    """``root`` as a Path (``~`` expanded); :class:`DatasetError` if it is not a folder."""
    root = Path(root).expanduser()
    if not root.is_dir():
        raise DatasetError(f"{what} root folder not found: {clip(str(root))}")
    return root


def select_sequences(available: list[str], requested: Iterable[str] | str | None, where: str,
                     annotation_of: Mapping[str, Path] | None = None) -> list[str]:
    """Names to load: all available, or the requested ones (case-insensitive match, each once).

    ``requested`` may be one comma-separated string. ``annotation_of`` maps the benchmark's
    other sequences (not available) to the annotation file that is missing, for a clearer error.
    """
    if requested is None:
        return available
    if isinstance(requested, str):
        requested = [s for s in requested.split(",") if s.strip()]
    if not requested:
        raise DatasetError(f"no sequence names given for {where}")
    by_lower: dict[str, list[str]] = {}
    for name in available:
        by_lower.setdefault(name.lower(), []).append(name)
    missing = {name.lower(): path for name, path in (annotation_of or {}).items()}
    chosen = []
    for want in (w.strip() for w in requested):
        if want in available:
            chosen.append(want)
        elif len(by_lower.get(want.lower(), [])) == 1:
            chosen.append(by_lower[want.lower()][0])
        else:
            raise _not_found(want, available, where, missing.get(want.lower()))
    return list(dict.fromkeys(chosen))


def _not_found(want: str, available: list[str], where: str, missing_annotation: Path | None) -> DatasetError:
    listed = ", ".join(available[:40]) + (" ..." if len(available) > 40 else "")
    if missing_annotation is not None:
        return DatasetError(f"sequence {shown(want)} of {where}: annotation file not found: "
                            f"{missing_annotation}. Available ({len(available)}): {listed or 'none'}")
    close = difflib.get_close_matches(want, available, n=1, cutoff=0.5)
    hint = f" Did you mean {close[0]!r}?" if close else ""
    return DatasetError(f"sequence {shown(want)} not found in {where}.{hint} "
                        f"Available ({len(available)}): {listed or 'none'}")


# --------------------------------------------------------------------------- the <seq>/img layout


def image_sequence_folders(root: Path) -> list[Path]:
    """Folders ``root/<seq>`` holding ``img/`` and a ``groundtruth_rect*.txt``: the layout that
    DTB70 and OTB share (in listing order, as detection has always sampled them). None under a
    root with ``data_seq/`` and ``anno/``: that is a UAV123 or UAVDT root, whatever else it holds."""
    if (root / "data_seq").is_dir() and (root / "anno").is_dir():
        return []
    return [p for p in root.iterdir() if p.is_dir() and (p / "img").is_dir()
            and any(p.glob("groundtruth_rect*.txt"))]


def first_frame_digits(folders: list[Path], sample: int = 10) -> set[int]:
    """Lengths of the first frame names (without extension) in the first ``sample`` ``img/``
    folders: ``{5}`` for DTB70's ``00001.jpg``, ``{4}`` for OTB's ``0001.jpg``."""
    return {len(os.path.splitext(f)[0]) for p in folders[:sample]
            for f in sorted(os.listdir(p / "img"))[:1]}
