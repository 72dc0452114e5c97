#!/usr/bin/env python3
"""Fits the light's six gains on fit_gains.py's cached part renders with
every view's brightest tops held within a band: the summed per-pixel
luminance error plus 10 times each view's tops ratio beyond the band,
minimised by Nelder-Mead from nine starts (the shipped gains, two
others, six random), gains kept at 0 or above.

    python3 docs/ground_truth/fit_tops.py --bins /tmp/transport_parts \\
        --cache /tmp/fit_transport --arrays /tmp/arrays --views backlit,high_sun,low_sun
"""

import argparse
import os
import sys

import numpy as np
from scipy.optimize import minimize

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import transport_figure as T  # noqa: E402

Y = np.array([0.2126, 0.7152, 0.0722])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bins", required=True, help="the parts' binaries")
    ap.add_argument("--cache", required=True, help="fit_gains.py's --cache, holding their renders")
    ap.add_argument("--arrays", required=True, help="compare.py --arrays output")
    ap.add_argument("--views", default="backlit,high_sun,low_sun")
    ap.add_argument("--held-out", default="",
                    help="views scored at the fitted gains but left out of the fit")
    ap.add_argument("--tops-band", type=float, default=0.095)
    a = ap.parse_args()
    data = {}
    fitted = a.views.split(",")
    held_out = [v for v in a.held_out.split(",") if v]
    for v in fitted + held_out:
        truth = np.load(os.path.join(a.arrays, f"{v}_mitsuba.npy"))
        cloud = np.load(os.path.join(a.arrays, f"{v}_cloud.npy"))
        zero = T.part(a.cache, a.bins, v, "zero")
        parts = np.stack([T.part(a.cache, a.bins, v, p) - zero for p in T.PARTS], -1)
        data[v] = (truth[cloud] @ Y, zero[cloud] @ Y, np.einsum("nck,c->nk", parts[cloud], Y))

    def scores(g, views=fitted):
        out = []
        for v in views:
            ym, z, parts = data[v]
            yo = z + parts @ g
            rel = (yo - ym) / ym
            out.append((np.abs(rel).mean(), np.percentile(yo, 99) / np.percentile(ym, 99),
                        rel.mean()))
        return out

    def objective(g):
        s = [(e, t) for e, t, _ in scores(np.maximum(g, 0))]
        return sum(e + 10 * max(0.0, abs(t - 1) - a.tops_band) for e, t in s)

    rng = np.random.default_rng(0)
    starts = [np.array([0.53, 0.46, 0.1, 1.19, 4.37, 3.82]),
              np.array([0.36, 0.02, 0.22, 0.76, 4.37, 0.0]),
              np.array([0.6, 0.3, 0.1, 0.7, 4.4, 1.0])]
    starts += [rng.uniform(0, 1, 6) * np.array([1, 1, 0.5, 2, 6, 6]) for _ in range(6)]
    best = min((minimize(objective, s, method="Nelder-Mead",
                         options={"maxiter": 4000, "xatol": 1e-4, "fatol": 1e-6})
                for s in starts), key=lambda r: r.fun)
    g = np.maximum(best.x, 0)
    print("gains " + " ".join(f"{x:.3f}" for x in g))
    for v, (e, t, b) in zip(fitted + held_out, scores(g, fitted + held_out)):
        note = "  (held out)" if v in held_out else ""
        print(f"  {v:9s} error {e:.4f}  bias {b:+.4f}  tops {t:.3f}{note}")


if __name__ == "__main__":
    main()
