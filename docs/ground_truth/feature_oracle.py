#!/usr/bin/env python3
"""How much of our error against the path tracer a correction by the
clouds' geometry around each pixel could remove: an oracle, fitted on
the pixels it is scored on (least squares on the log ratio, linear and
with squares, no cross terms), so an estimate of what a light term
built on these inputs could do at best, not a strict bound.

    python3 docs/ground_truth/compare.py --width 80 --height 60 --spp 1024 \\
        --cells 1024 --supersample 4 --cache /tmp/gt --arrays --out /tmp/gt/arrays
    python3 docs/ground_truth/feature_oracle.py --arrays /tmp/gt/arrays --views backlit,side

For each cloud pixel (compare.py's mask) it finds where the view ray's
optical depth through the exported grid (256 cells, about 39 m) reaches
1, and there measures:
- the optical depth toward the sun through the grid and through the
  grid blurred by a Gaussian of 2, 4 and 8 cells (the sun's shadow at
  the scale of a cloud's parts and of a whole cloud);
- the blurred grid's extinction there (how much cloud is around);
- the optical depth straight up, straight down and on along the view ray
  (how deep the cloud is above, below and behind the point);
- its height in the band.

Then it prints, per view, each feature's correlation with the log of
Mitsuba's luminance over ours (per pixel, and both smoothed over a
Gaussian of 3 pixels on the cloud pixels), and the per-pixel error left
after scaling ours by `exp` of the least-squares fit of that log ratio
on each feature alone and on all of them together.
"""

import argparse
import os
import sys

import numpy as np
from scipy.ndimage import gaussian_filter

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import compare as C  # noqa: E402

Y = np.array([0.2126, 0.7152, 0.0722])
STEP_M = 5.0
BLURS = (2, 4, 8)


def depth_along(grid, side, start, direction, length):
    """Optical depth from `start` along `direction` (one or per pixel)."""
    tau = np.zeros(start.shape[:-1])
    for t in np.arange(0.0, length, STEP_M):
        tau += C.grid_extinction(grid, side, start + direction * t) * STEP_M
    return tau


def features(vol, side, width, height):
    """(found, {name: per-pixel feature}); `found`: the ray reaches depth 1."""
    eye, dirs = C.camera_rays(side, width, height)
    sun = np.array(side["sun_direction"]) / np.linalg.norm(side["sun_direction"])
    shape = (height, width)
    depth, hit = np.zeros(shape), np.full(shape + (3,), np.nan)
    for t in np.arange(0.0, 20000.0, STEP_M):
        p = eye + dirs * t
        new = depth + C.grid_extinction(vol, side, p) * STEP_M
        first = (depth < 1.0) & (new >= 1.0)
        hit[first] = p[first]
        depth = new
    found = ~np.isnan(hit[..., 0])
    start = np.where(found[..., None], hit, eye)
    out = {"sun depth": depth_along(vol, side, start, sun, 12000.0)}
    for s in BLURS:
        blurred = gaussian_filter(vol, s, mode="nearest").astype(np.float32)
        out[f"sun depth, blurred {s} cells"] = depth_along(blurred, side, start, sun, 12000.0)
        out[f"extinction, blurred {s} cells"] = C.grid_extinction(blurred, side, start)
    out["depth up"] = depth_along(vol, side, start, np.array([0.0, 1.0, 0.0]), 6000.0)
    out["depth down"] = depth_along(vol, side, start, np.array([0.0, -1.0, 0.0]), 6000.0)
    out["depth on along the view"] = depth_along(vol, side, start, dirs, 6000.0)
    feats = {k: np.log1p(v) for k, v in out.items()}
    lo, hi = side["box_min_m"][1], side["box_max_m"][1]
    feats["height in the band"] = (start[..., 1] - lo) / (hi - lo)
    return found, feats


def corrected_error(ours, truth, cloud, mask, columns):
    """The per-pixel error after scaling ours on `mask` by exp of the
    least-squares fit of log(truth / ours) on `columns`."""
    x = np.stack([c[mask] for c in columns] + [np.ones(int(mask.sum()))], 1)
    r = np.log(np.maximum(truth[mask], 1e-9) / np.maximum(ours[mask], 1e-9))
    coef, *_ = np.linalg.lstsq(x, r, rcond=None)
    fixed = ours.copy()
    fixed[mask] = ours[mask] * np.exp(x @ coef)
    return float(np.abs((fixed - truth) / truth)[cloud].mean())


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--arrays", required=True,
                    help="compare.py --arrays output: VIEW_ours.npy, VIEW_mitsuba.npy, VIEW_cloud.npy")
    ap.add_argument("--views", default="backlit")
    ap.add_argument("--bin", default=os.path.join(C.ROOT, "target/release/cumulus"))
    a = ap.parse_args()
    for view in a.views.split(","):
        ours = np.load(os.path.join(a.arrays, f"{view}_ours.npy")) @ Y
        truth = np.load(os.path.join(a.arrays, f"{view}_mitsuba.npy")) @ Y
        cloud = np.load(os.path.join(a.arrays, f"{view}_cloud.npy"))
        height, width = ours.shape
        found, feats = features(*C.export_view(view, a.bin, width, height), width, height)
        mask = cloud & found
        weight = mask.astype(float)

        def smooth(x):
            return gaussian_filter(np.where(mask, x, 0.0), 3) / np.maximum(gaussian_filter(weight, 3), 1e-6)

        ratio = np.log(np.maximum(truth, 1e-9) / np.maximum(ours, 1e-9))
        # Outside the mask both smoothed images are 0 (only the mask is read).
        with np.errstate(invalid="ignore", divide="ignore"):
            smooth_ratio = np.log(smooth(truth) / smooth(ours))
        now = float(np.abs((ours - truth) / truth)[cloud].mean())
        print(f"{view}: {int(cloud.sum())} cloud pixels ({int(mask.sum())} reach depth 1 in the "
              f"256-cell grid), per-pixel error {now:.4f}; log(Mitsuba / ours) smoothed over "
              f"3 pixels has a standard deviation of {smooth_ratio[mask].std():.3f}")
        print(f"  {'feature':34s} corr. per pixel  smoothed  error, fitted alone")
        for name, f in feats.items():
            c = np.corrcoef(f[mask], ratio[mask])[0, 1]
            cs = np.corrcoef(smooth(f)[mask], smooth_ratio[mask])[0, 1]
            e = corrected_error(ours, truth, cloud, mask, [f])
            print(f"  {name:34s} {c:+.2f}            {cs:+.2f}      {e:.4f}")
        e = corrected_error(ours, truth, cloud, mask, list(feats.values()))
        print(f"  all together (linear, in-sample): {e:.4f}")
        sq = list(feats.values()) + [f * f for f in feats.values()]
        e = corrected_error(ours, truth, cloud, mask, sq)
        print(f"  all together with their squares: {e:.4f}")


if __name__ == "__main__":
    main()
