#!/usr/bin/env python3
"""A view as the shipped diffusion and as the transported light volume
light it, each at its own fitted gains, beside the path tracer's
reference, with each one's relative luminance error (green 0, red 50 %
or more), from fit_gains.py's cached part renders:

    python3 docs/ground_truth/transport_figure.py --view backlit \\
        --diffusion /tmp/parts --diffusion-cache /tmp/fitcache \\
        --diffusion-gains 0.585,0.199,0,1.355,4.322,4.885 \\
        --transport /tmp/transport_parts --transport-cache /tmp/fit_transport \\
        --transport-gains 0.451,0,0,0.841,4.413,0.205 \\
        --arrays /tmp/arrays --out docs/ground_truth/backlit_transport.png
"""

import argparse
import os
import sys

import numpy as np
from PIL import Image

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import compare as C  # noqa: E402

PARTS = ["mf", "mi", "di", "fl", "am", "gr"]


def part(cache, bins, view, name):
    """fit_gains.py's cached render of `view` by `bins`/cumulus_`name`."""
    st = os.stat(os.path.join(bins, f"cumulus_{name}"))
    path = os.path.join(cache, f"{view}_cumulus_{name}_{st.st_size}_{int(st.st_mtime)}_80x60x4_.npy")
    return np.load(path)


def image(cache, bins, view, gains):
    zero = part(cache, bins, view, "zero")
    return zero + sum(g * (part(cache, bins, view, p) - zero) for g, p in zip(gains, PARTS))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--view", default="backlit")
    for which in ("diffusion", "transport"):
        ap.add_argument(f"--{which}", required=True, help="the parts' binaries")
        ap.add_argument(f"--{which}-cache", required=True, help="fit_gains.py's --cache")
        ap.add_argument(f"--{which}-gains", required=True, help="six gains, comma-separated")
    ap.add_argument("--arrays", required=True, help="compare.py --arrays output")
    ap.add_argument("--exposure", type=float, default=1.2)
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    truth = np.load(os.path.join(a.arrays, f"{a.view}_mitsuba.npy"))
    cloud = np.load(os.path.join(a.arrays, f"{a.view}_cloud.npy"))
    rows = []
    for bins, cache, gains in ((a.diffusion, a.diffusion_cache, a.diffusion_gains),
                               (a.transport, a.transport_cache, a.transport_gains)):
        ours = image(cache, bins, a.view, [float(g) for g in gains.split(",")])
        rel = (C.luminance(ours) - C.luminance(truth)) / np.maximum(C.luminance(truth), 1e-6)
        err = np.clip(np.abs(rel) / 0.5, 0, 1)
        err_img = np.stack([err * 255, (1 - err) * 255 * cloud, np.zeros_like(err)], axis=2)
        err_img = np.where(cloud[..., None], err_img, 0).astype(np.uint8)
        rows.append(np.concatenate([C.aces(ours, a.exposure), C.aces(truth, a.exposure), err_img],
                                   axis=1))
        print(f"{bins}: per-pixel error {np.abs(rel[cloud]).mean():.4f}")
    strip = np.concatenate(rows, axis=0)
    strip = np.repeat(np.repeat(strip, C.FIGURE_SCALE, axis=0), C.FIGURE_SCALE, axis=1)
    Image.fromarray(strip).save(a.out)


if __name__ == "__main__":
    main()
