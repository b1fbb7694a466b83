"""Bounds on memory and time that depend on the machine or the study, so a user may raise
them: environment variables read when used (a program may set them before tracking).

``$DCFKIT_MAX_IMAGE_PIXELS`` (default 10^8)
    the most pixels of one image: a frame read from a file (checked from its header before
    decoding) or a video, or a region copied from a frame for one sample.
``$DCFKIT_MAX_SAMPLE_PIXELS`` (default 2048²)
    one frame's samples: the search samples at every search scale (in feature cells, a
    sixteenth of it), and the scale filter's samples and working patch.
``$DCFKIT_MAX_VARIANTS`` (default :data:`dcfkit.ablation.spec.MAX_VARIANTS`, 1,000)
    the variants of one ablation spec, named ones and grid points: each is resolved when the
    spec is read (``dcfkit ablate --max-variants`` sets it for one command).
"""
from __future__ import annotations

import math
import os

from dcfkit.errors import ConfigError, shown

IMAGE_PIXELS_VARIABLE = "DCFKIT_MAX_IMAGE_PIXELS"
DEFAULT_MAX_IMAGE_PIXELS = 10**8  # 300 MB as BGR; an 8K video frame has 33 million


def env_limit(variable: str, default: int, unit: str = "pixels") -> int:
    """A limit, a count of ``unit``: the environment variable ``variable`` if set (``1e9`` is
    fine), else ``default``; read when used, so a program may set it before tracking."""
    text = os.environ.get(variable, "").strip()
    if not text:
        return default
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (1 <= value < math.inf):
        raise ConfigError(f"${variable} must be a number of {unit} >= 1, got {shown(text)}")
    return int(value)


def max_image_pixels() -> int:
    """The most pixels dcfkit holds in one image: a frame it reads from a file, or a region it
    copies from a frame for one sample (``$DCFKIT_MAX_IMAGE_PIXELS``, default 10^8)."""
    return env_limit(IMAGE_PIXELS_VARIABLE, DEFAULT_MAX_IMAGE_PIXELS)


SAMPLE_PIXELS_VARIABLE = "DCFKIT_MAX_SAMPLE_PIXELS"
DEFAULT_MAX_SAMPLE_PIXELS = 2048**2  # 20 times the shipped configs' 5 x 200² (STRCF, BACF)
CELL_AREA = 16  # the cell budget: as many cells as the pixel budget has 4x4-pixel cells


def sample_budget() -> tuple[int, int]:
    """(pixels, cells) one frame's samples may have: the search samples at every search scale,
    in pixels and in feature cells, and the scale filter's samples (``$DCFKIT_MAX_SAMPLE_PIXELS``,
    default 2048²; cells: a sixteenth of it). Beyond them memory and time per frame grow without
    bound (features are ``channels x cells`` floats)."""
    pixels = env_limit(SAMPLE_PIXELS_VARIABLE, DEFAULT_MAX_SAMPLE_PIXELS)
    return pixels, max(pixels // CELL_AREA, 1)


VARIANTS_VARIABLE = "DCFKIT_MAX_VARIANTS"


def max_variants(default: int) -> int:
    """The most variants of one ablation spec: ``$DCFKIT_MAX_VARIANTS`` if set, else ``default``
    (:data:`dcfkit.ablation.spec.MAX_VARIANTS`)."""
    return env_limit(VARIANTS_VARIABLE, default, "variants")
