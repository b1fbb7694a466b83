"""Synthetic aerial-like sequences generated in code, for demos and tests without data.

A textured ground plane seen by a drifting, shaking camera; a textured target moving on a
smooth path; optionally a look-alike distractor whose path passes close to the target
half-way through. Deterministic for a given seed. Ground truth boxes are (x, y, w, h),
0-based pixels.
"""
from __future__ import annotations

import dataclasses

import cv2
import numpy as np


@dataclasses.dataclass
class SyntheticSequence:
    name: str
    frames: list[np.ndarray]      # (H, W, 3) uint8 BGR
    ground_truth: np.ndarray      # (N, 4) float64 boxes
    distractor: np.ndarray | None = None  # (N, 4) float64 boxes of the look-alike, if there is one


def _texture(rng: np.random.Generator, shape: tuple[int, int], scales=(64, 16, 4)) -> np.ndarray:
    """Multi-octave smooth noise in [0, 1], (H, W) float32."""
    out = np.zeros(shape, np.float32)
    for i, s in enumerate(scales):
        small = rng.random((max(shape[0] // s, 2), max(shape[1] // s, 2))).astype(np.float32)
        out += cv2.resize(small, shape[::-1], interpolation=cv2.INTER_CUBIC) / (i + 1)
    out -= out.min()
    return out / max(float(out.max()), 1e-6)


def _ground(rng, shape) -> np.ndarray:
    """Fields, a road grid and scattered bushes: (H, W, 3) uint8."""
    t = _texture(rng, shape)
    fine = _texture(rng, shape, scales=(8, 2))
    colour = np.stack([60 + 50 * t, 90 + 70 * t, 70 + 60 * (1 - t)], axis=-1) + 25 * (fine[..., None] - 0.5)
    img = np.clip(colour, 0, 255).astype(np.uint8)
    for y in range(40, shape[0], 170):
        cv2.rectangle(img, (0, y), (shape[1], y + 14), (120, 125, 128), -1)
    for x in range(60, shape[1], 230):
        cv2.rectangle(img, (x, 0), (x + 14, shape[0]), (120, 125, 128), -1)
    for _ in range(shape[0] * shape[1] // 4000):
        c = (int(rng.integers(0, shape[1])), int(rng.integers(0, shape[0])))
        cv2.circle(img, c, int(rng.integers(3, 9)), (40, int(rng.integers(70, 110)), 40), -1)
    return img


def _sprite(rng, size: tuple[int, int], tint: tuple[int, int, int]) -> np.ndarray:
    """A vehicle-like textured rectangle (h, w, 3) uint8."""
    h, w = size
    body = np.zeros((h, w, 3), np.float32)
    body[:] = tint
    body += 60 * (_texture(rng, (h, w), scales=(4, 2))[..., None] - 0.5)
    body[h // 4: 3 * h // 4, w // 5: w // 2] *= 0.45        # windscreen
    body[h // 3: 2 * h // 3, 3 * w // 4: w - 2] += 50        # roof light
    return np.clip(body, 0, 255).astype(np.uint8)


def _paste(frame: np.ndarray, sprite: np.ndarray, x: float, y: float) -> None:
    h, w = sprite.shape[:2]
    x0, y0 = int(round(x)), int(round(y))
    fy0, fx0 = max(y0, 0), max(x0, 0)
    fy1, fx1 = min(y0 + h, frame.shape[0]), min(x0 + w, frame.shape[1])
    if fy1 > fy0 and fx1 > fx0:
        frame[fy0:fy1, fx0:fx1] = sprite[fy0 - y0: fy1 - y0, fx0 - x0: fx1 - x0]


def make_sequence(n_frames: int = 120, size: tuple[int, int] = (360, 480), target: tuple[int, int] = (22, 36),
                  distractor: bool = True, seed: int = 0, speed: float = 3.0) -> SyntheticSequence:
    """Generate a sequence: ``size`` (H, W) frames, ``target`` (h, w) sprite."""
    rng = np.random.default_rng(seed)
    H, W = size
    world = _ground(rng, (2 * H, 2 * W))
    sprite = _sprite(rng, target, (40, 50, 200))
    twin = _sprite(rng, target, (48, 56, 190))                 # a look-alike distractor
    t = np.arange(n_frames, dtype=float)
    drift = np.stack([H / 2 + 0.2 * t * speed, W / 2 + 0.3 * t * speed], axis=1)
    cam = drift + 3 * rng.standard_normal((n_frames, 2))       # camera drift plus shake
    # target path in world coordinates: a slow curve across the view
    ty = drift[:, 0] + H * 0.5 + 40 * np.sin(t / n_frames * 2 * np.pi)
    tx = drift[:, 1] + W * 0.3 + speed * t * 0.5
    # distractor: drives against the target and passes 1.4 target heights away half-way through
    mid = n_frames / 2
    dy_path = ty + 1.4 * target[0] + 0.3 * (t - mid)
    dx_path = tx + 2.2 * speed * (mid - t)
    frames, boxes, twins = [], [], []
    for k in range(n_frames):
        cy, cx = int(round(cam[k, 0])), int(round(cam[k, 1]))
        frame = world[cy: cy + H, cx: cx + W].copy()
        if distractor:
            _paste(frame, twin, dx_path[k] - cx, dy_path[k] - cy)
        x, y = tx[k] - cx, ty[k] - cy
        _paste(frame, sprite, x, y)
        gain = 1.0 + 0.15 * np.sin(k / 17.0)                   # illumination change
        noisy = frame.astype(np.float32) * gain + rng.normal(0, 4, frame.shape)
        frames.append(np.clip(noisy, 0, 255).astype(np.uint8))
        boxes.append((float(round(x)), float(round(y)), float(target[1]), float(target[0])))
        twins.append((float(round(dx_path[k] - cx)), float(round(dy_path[k] - cy)), float(target[1]), float(target[0])))
    return SyntheticSequence("synthetic", frames, np.array(boxes), np.array(twins) if distractor else None)
