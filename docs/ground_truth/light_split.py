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
"""

import argparse
import os

import numpy as np
from scipy.ndimage import gaussian_filter

Y = np.array([0.2126, 0.7152, 0.0722])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("full", help="compare.py --arrays output, the full light")
    ap.add_argument("single", help="compare.py --single-scattering --arrays output")
    ap.add_argument("--view", default="backlit")
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


if __name__ == "__main__":
    main()
