"""Where a view's per-pixel error lives: in the sun's light scattered once
or in the rest (the multiply scattered sun and the sky), at which optical
depths, and at which scale.

Reads compare.py's --arrays output twice, for the full light (DIR_FULL)
and for single scattering (DIR_SINGLE, compare.py --single-scattering),
and optionally a second Mitsuba render of the full light (noise_floor.py's
cache entry, *_seed5000.npy), averaged with the first as the reference:

    python3 docs/ground_truth/compare.py --width 80 --height 60 --spp 1024 \\
        --cells 1024 --supersample 4 --cache /tmp/gt --arrays --out /tmp/full
    python3 docs/ground_truth/compare.py --width 80 --height 60 --spp 1024 \\
        --cells 1024 --supersample 4 --single-scattering --views backlit \\
        --cache /tmp/gt_single --arrays --out /tmp/single
    python3 docs/ground_truth/light_split.py --view backlit /tmp/full /tmp/single \\
        --second /tmp/gt/backlit_80x60_1024spp_1024cells_seed5000.npy

Prints: the per-pixel error as it is, were our single scattering
Mitsuba's, and were our multiply scattered light Mitsuba's; the ratio of
Mitsuba's multiply scattered light to ours by the view's optical depth;
and the per-pixel error once our multiply scattered light is corrected
by the ratio smoothed over the cloud pixels with a Gaussian of sigma
pixels (how large the error's structures are).

With --geometry it also exports the view's volume (256 cells, the same
scene as compare.py's) and finds, for each pixel, where the view ray's
optical depth through the grid reaches 1, the optical depth from there
toward the sun, and the ray's angle to the sun. It prints the ratio by
that sun depth, and the per-pixel error after our multiply scattered
light is scaled, bin by bin, by the best factor for that bin (a grid
search against Mitsuba, fitted on the pixels it is scored on), for bins
of the view's optical depth, of the sun depth, of the angle, and of all
three together: how far a correction by those variables alone gets
(optimistic for small bins; finer bins or a smooth function could go
somewhat lower). Cloud pixels whose ray never reaches depth 1 in the
256-cell grid get a sun-depth bin of their own (their count is
printed).
"""

import argparse
import os
import sys

import numpy as np
from scipy.ndimage import gaussian_filter

Y = np.array([0.2126, 0.7152, 0.0722])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("full", help="compare.py --arrays output, the full light")
    ap.add_argument("single", help="compare.py --single-scattering --arrays output")
    ap.add_argument("--view", default="backlit")
    ap.add_argument("--geometry", action="store_true",
                    help="bin by the sun's optical depth from the first hit and the angle "
                         "to the sun, and print the best-scale bound per bin")
    ap.add_argument("--bin", default=os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                                  "..", "..", "target", "release", "cumulus"),
                    help="the cumulus binary that exports the volume (--geometry)")
    ap.add_argument("--second", default=None,
                    help="a second Mitsuba render of the full light (.npy), averaged "
                         "with the first")
    a = ap.parse_args()
    load = lambda d, what: np.load(os.path.join(d, f"{a.view}_{what}.npy"))
    truth = load(a.full, "mitsuba")
    if a.second:
        second = np.load(a.second)
        if second.shape != truth.shape:
            raise SystemExit(f"--second {a.second}: shape {second.shape}, "
                             f"expected {truth.shape}")
        truth = 0.5 * (truth + second)
    t, o = truth @ Y, load(a.full, "ours") @ Y
    ts, os_ = load(a.single, "mitsuba") @ Y, load(a.single, "ours") @ Y
    cloud, tau = load(a.full, "cloud"), load(a.full, "tau")
    tm, om = t - ts, o - os_
    err = lambda img: np.abs((img - t) / t)[cloud].mean()
    print(f"{a.view}: {int(cloud.sum())} cloud pixels")
    print(f"  per-pixel error {err(o):.4f}; were our single scattering Mitsuba's "
          f"{err(ts + om):.4f}; were the rest Mitsuba's {err(os_ + tm):.4f}")
    print(f"  single scattering, mean: Mitsuba {ts[cloud].mean():.4f}, ours "
          f"{os_[cloud].mean():.4f}; the rest: Mitsuba {tm[cloud].mean():.4f}, "
          f"ours {om[cloud].mean():.4f}")
    print("  the rest, Mitsuba's over ours, by the view's optical depth:")
    for lo, hi in [(1, 3), (3, 6), (6, 12), (12, np.inf)]:
        m = cloud & (tau >= lo) & (tau < hi)
        if m.any():
            print(f"    tau {lo}-{hi}: {tm[m].sum() / om[m].sum():.3f} ({int(m.sum())} pixels)")
    print("  per-pixel error with the rest corrected by the ratio smoothed over sigma pixels:")
    c = cloud.astype(float)
    for sigma in [1, 2, 3, 5, 8, 12]:
        k = gaussian_filter(tm * c, sigma) / np.maximum(gaussian_filter(om * c, sigma), 1e-9)
        print(f"    sigma {sigma:2d}: {err(os_ + om * k):.4f}")
    if a.geometry:
        sun_tau, angle = view_geometry(a.view, a.bin, t.shape)
        missing = cloud & np.isnan(sun_tau)
        print(f"  geometry: {int(missing.sum())} cloud pixels never reach depth 1 in the "
              "256-cell grid; they get a sun-depth bin of their own")
        print("  the rest, Mitsuba's over ours, by the sun's optical depth from where the "
              "view's reaches 1:")
        for lo, hi in [(0, 2), (2, 5), (5, 10), (10, 20), (20, np.inf)]:
            m = cloud & (sun_tau >= lo) & (sun_tau < hi)
            if m.any():
                print(f"    sun tau {lo}-{hi}: {tm[m].sum() / om[m].sum():.3f} "
                      f"({int(m.sum())} pixels)")
        bins = {
            "view tau": np.digitize(tau, [3, 6, 12]),
            "sun tau": np.where(np.isnan(sun_tau), 9,
                                np.digitize(np.nan_to_num(sun_tau), [2, 5, 10, 20])),
            "angle to the sun": np.digitize(angle, [10, 20, 30]),
        }
        bins["all three"] = sum(b * 10 ** i for i, b in enumerate(bins.values()))
        print("  per-pixel error with the rest scaled by the best factor of each bin:")
        for name, labels in bins.items():
            fixed = o.copy()
            for label in np.unique(labels[cloud]):
                m = cloud & (labels == label)
                scales = np.linspace(0.3, 2.5, 111)
                errors = [np.abs((o[m] + (k - 1) * om[m] - t[m]) / t[m]).mean() for k in scales]
                fixed[m] = o[m] + (scales[int(np.argmin(errors))] - 1) * om[m]
            print(f"    {name:17s} ({len(np.unique(labels[cloud])):2d} bins): {err(fixed):.4f}")


def view_geometry(view, binary, shape):
    """For each pixel of compare.py's `view`: the optical depth toward the
    sun from the point where the view ray's optical depth through the
    exported grid (256 cells) reaches 1, and the ray's angle to the sun,
    degrees. Pixels whose ray never reaches 1 get NaN."""
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import compare as C

    height, width = shape
    vol, side = C.export_view(view, binary, width, height)

    def sigma(p):
        return C.grid_extinction(vol, side, p)

    eye, dirs = C.camera_rays(side, width, height)
    sun = np.array(side["sun_direction"]) / np.linalg.norm(side["sun_direction"])
    step = 5.0
    depth, hit = np.zeros(shape), np.full(shape + (3,), np.nan)
    for t in np.arange(0.0, 20000.0, step):
        p = eye + dirs * t
        new = depth + sigma(p) * step
        first = (depth < 1.0) & (new >= 1.0)
        hit[first] = p[first]
        depth = new
    found = ~np.isnan(hit[..., 0])
    start = np.where(found[..., None], hit, eye)
    sun_tau = np.zeros(shape)
    for t in np.arange(0.0, 12000.0, step):
        sun_tau += sigma(start + sun * t) * step
    angle = np.degrees(np.arccos(np.clip(dirs @ sun, -1.0, 1.0)))
    return np.where(found, sun_tau, np.nan), angle


if __name__ == "__main__":
    main()
