#!/usr/bin/env python3
"""Where a frame's error against the path-traced truth lives: per pixel or over blocks.

  fiber_scale_error.py blocks TRUTH.exr WIDTH FRAME.exr...
      Each frame box-filtered to WIDTH pixels across (frames rendered at 2x or 4x WIDTH are thus
      supersampled), against the truth box-filtered to the same width, then over 2..16-pixel
      blocks: relative RMSE over the truth's hair pixels, mean against the truth's, alpha's error.

Used by scripts/fiber-scale-error.sh (docs/BENCHMARKS.md, "Fiber scale"). Reads EXR through
Mitsuba 3's Bitmap, which the ground truth already needs.
"""
import sys

import numpy as np


def load(path):
    import mitsuba as mi

    mi.set_variant("scalar_rgb")
    image = np.array(mi.Bitmap(path), dtype=np.float64)
    if image.ndim != 3 or image.shape[2] != 4:
        sys.exit(f"{path}: expected an RGBA image, got shape {image.shape}")
    return image


def box(image, k):
    h, w, c = image.shape
    return image[: h // k * k, : w // k * k].reshape(h // k, k, w // k, k, c).mean(axis=(1, 3))


def to_width(image, width, path):
    k = image.shape[1] // width
    if k < 1 or image.shape[1] != k * width:
        sys.exit(f"{path}: {image.shape[1]} pixels across is not a multiple of {width}")
    return box(image, k) if k > 1 else image


def relative_rmse(x, t, mask):
    return np.sqrt(((x - t) ** 2)[mask].sum() / (t**2)[mask].sum())


def blocks(truth_path, width, frames):
    truth = to_width(load(truth_path), width, truth_path)
    print("| frame | per pixel | 2×2 | 4×4 | 8×8 | 16×16 | mean / truth's | alpha per pixel |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    for path in frames:
        frame = to_width(load(path), width, path)
        if frame.shape != truth.shape:
            sys.exit(f"{path}: {frame.shape[1]}x{frame.shape[0]} against the truth's "
                     f"{truth.shape[1]}x{truth.shape[0]} (another aspect)")
        hair = truth[..., 3] > 0
        cells = []
        for k in (1, 2, 4, 8, 16):
            t, x = box(truth, k), box(frame, k)
            cells.append(f"{relative_rmse(x[..., :3], t[..., :3], t[..., 3] > 0):.3f}")
        mean = frame[..., :3][hair].mean() / truth[..., :3][hair].mean()
        alpha = relative_rmse(frame[..., 3], truth[..., 3], hair)
        print(f"| {path.split('/')[-1]} | " + " | ".join(cells) + f" | {mean:.3f} | {alpha:.3f} |")


if __name__ == "__main__":
    if len(sys.argv) >= 5 and sys.argv[1] == "blocks":
        blocks(sys.argv[2], int(sys.argv[3]), sys.argv[4:])
    else:
        sys.exit(__doc__)
