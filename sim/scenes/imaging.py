"""Image helpers shared by render, demo and the reports: 8-bit images, PSNR, panels, PNG."""

from pathlib import Path

import numpy as np
from PIL import Image

from bumprtl.sim.golden.common import to_8bit

__all__ = ["compose", "psnr", "max_diff", "panel", "save_png"]


def compose(scene, color):
    """Per-pixel intensity in [0, 1] -> 8-bit RGB image: times the albedo texture when the
    scene has one, black outside the geometry."""
    rgb = np.repeat(np.asarray(color, float)[..., None], 3, axis=-1)
    if scene.albedo is not None:
        rgb = rgb * scene.albedo[scene.v, scene.u]
    return np.where(scene.mask[..., None], to_8bit(rgb), 0).astype(np.uint8)


def psnr(ref, img):
    """Peak signal-to-noise ratio of two 8-bit images in dB (inf when identical)."""
    mse = np.mean((np.asarray(ref, float) - np.asarray(img, float)) ** 2)
    return float("inf") if mse == 0 else float(10 * np.log10(255.0 ** 2 / mse))


def max_diff(ref, img):
    return int(np.max(np.abs(np.asarray(ref, int) - np.asarray(img, int))))


def panel(ref, img, gain=10):
    """reference | method | |difference| x gain, side by side with 4-pixel gutters."""
    diff = np.clip(np.abs(np.asarray(ref, int) - np.asarray(img, int)) * gain, 0, 255).astype(np.uint8)
    gutter = np.full((ref.shape[0], 4) + ref.shape[2:], 255, np.uint8)
    return np.concatenate([ref, gutter, img, gutter, diff], axis=1)


def save_png(path, img):
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray(np.asarray(img, np.uint8)).save(path, optimize=False)
    return path
