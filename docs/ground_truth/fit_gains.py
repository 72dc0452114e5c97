#!/usr/bin/env python3
"""Fits the light's six gains (the octaves' forward and isotropic
parts, the diffused sunlight's, the light volume's, the sky's and the
ground's) on the renderer's own
images, against the path tracer's references.

    python3 docs/ground_truth/compare.py --width 80 --height 60 --spp 1024 --cells 1024 \\
        --supersample 4 --cache /tmp/gt --arrays --out /tmp/gt/arrays
    docs/ground_truth/gain_parts.sh /tmp/parts
    python3 docs/ground_truth/fit_gains.py --bins /tmp/parts --arrays /tmp/gt/arrays

Each view is rendered by each of gain_parts.sh's builds (CPU, 4x
supersampled as compare.py does); the image is linear in the gains, so
a set of gains is the zero build's image plus the parts', and every
candidate is scored in milliseconds. Prints, per fit, the gains and each
view's mean relative luminance error, bias, tops ratio and red over
blue (ours over Mitsuba's) on compare.py's cloud pixels. Fits: least
squares on the relative error; Nelder-Mead on the summed per-pixel
errors; the same plus |log| of the red-over-blue ratios (then Powell),
optionally with the brightest tops held near 1 and some gains held. The
shipped gains (2026-12-04):

    python3 docs/ground_truth/fit_gains.py --bins /tmp/parts --arrays /tmp/gt/arrays \\
        --colour-weight 0.1 --tops-band 0.095 --hold di=0.1
"""

import argparse
import os
import sys
import tempfile

import numpy as np
from scipy.optimize import minimize

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import compare as C  # noqa: E402
from surrogate import SIX, shipped_gains  # noqa: E402

Y = np.array([0.2126, 0.7152, 0.0722])
PARTS = ["mf", "mi", "di", "fl", "am", "gr"]


def render(binary, name, width, height, ss, extra, tmp):
    """Our linear image of view `name` by `binary`, averaged per pixel."""
    _, base, el, az, yaw = next(v for v in C.ALL_VIEWS if v[0] == name)
    scene = os.path.join(C.ROOT, "scenes", f".fit_{name}_{os.getpid()}.toml")
    C.scene_variant(base, el, az, yaw, width * ss, height * ss, scene,
                    {**C.VIEW_CAMERA.get(name, {}), **extra})
    exr = os.path.join(tmp, f"{name}.exr")
    try:
        C.run([binary, "render", "--scene", scene, "--backend", "cpu", "--out", exr])
    finally:
        os.remove(scene)
    return C.read_exr(exr).reshape(height, ss, width, ss, 3).mean(axis=(1, 3))


def cached_render(a, binary, name, extra, tmp):
    """`render`, read from `a.cache` when that binary (same size and
    modification time) rendered the view with the same keys before."""
    if not a.cache:
        return render(binary, name, a.width, a.height, a.supersample, extra, tmp)
    st = os.stat(binary)
    keys = "_".join(f"{k}={v}" for k, v in sorted(extra.items()))
    path = os.path.join(a.cache, f"{name}_{os.path.basename(binary)}_{st.st_size}_{int(st.st_mtime)}_"
                                 f"{a.width}x{a.height}x{a.supersample}_{keys}.npy")
    if not os.path.exists(path):
        C.save_cached(path, render(binary, name, a.width, a.height, a.supersample, extra, tmp))
    return np.load(path)


def scores(data, g):
    out = []
    for truth, zero, parts in data.values():
        img = zero + parts @ g
        yo, ym = img @ Y, truth @ Y
        rel = (yo - ym) / ym
        rb = (img[:, 0].mean() / img[:, 2].mean()) / (truth[:, 0].mean() / truth[:, 2].mean())
        out.append((np.abs(rel).mean(), rel.mean(), np.percentile(yo, 99) / np.percentile(ym, 99), rb))
    return out


def show(label, data, g):
    print(f"{label}: gains " + " ".join(f"{x:.3f}" for x in g))
    for name, (e, b, t, rb) in zip(data, scores(data, g)):
        print(f"  {name:9s} error {e:.4f}  bias {b:+.4f}  tops {t:.3f}  red/blue {rb:.3f}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bins", required=True, help="gain_parts.sh's output directory")
    ap.add_argument("--arrays", required=True,
                    help="compare.py --arrays output: VIEW_mitsuba.npy and VIEW_cloud.npy")
    ap.add_argument("--views", default=",".join(v[0] for v in C.VIEWS))
    ap.add_argument("--width", type=int, default=80)
    ap.add_argument("--height", type=int, default=60)
    ap.add_argument("--supersample", type=int, default=4)
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="a [render] key for our renders (e.g. shadow_steps=32)")
    ap.add_argument("--colour-weight", type=float, default=1.0,
                    help="the weight of the colour term in the last fit (default 1)")
    ap.add_argument("--tops-band", type=float, default=None, metavar="FRACTION",
                    help="in the last fit, a penalty (5 per unit) on each view's brightest-tops "
                         "ratio outside 1 ± FRACTION (the shipped fit: 0.095)")
    ap.add_argument("--hold", action="append", default=[], metavar="PART=GAIN",
                    help="hold a part's gain in the last fit (e.g. di=0.1); repeatable")
    ap.add_argument("--cache", help="keep each render here, keyed by the binary's size and "
                                    "time and the --set keys: a rebuilt part renders again, "
                                    "the others are read back")

    a = ap.parse_args()
    C.exit_on_sigterm()
    held = {}
    for h in a.hold:
        k, _, v = h.partition("=")
        try:
            held[PARTS.index(k)] = float(v)
        except ValueError:
            sys.exit(f"--hold {h}: expected PART=GAIN, a number, with PART one of {', '.join(PARTS)}")
    extra = dict(kv.split("=", 1) for kv in a.set)
    data = {}
    with tempfile.TemporaryDirectory() as tmp:
        for name in a.views.split(","):
            truth = np.load(os.path.join(a.arrays, f"{name}_mitsuba.npy"))
            cloud = np.load(os.path.join(a.arrays, f"{name}_cloud.npy"))
            imgs = {v: cached_render(a, os.path.join(a.bins, f"cumulus_{v}"), name, extra, tmp)[cloud]
                    for v in ["zero"] + PARTS}
            parts = np.stack([imgs[v] - imgs["zero"] for v in PARTS], -1)
            data[name] = (truth[cloud], imgs["zero"], parts)
            print(f"{name}: rendered", flush=True)
    # MULTIPLE_GAIN, MULTIPLE_ISOTROPIC_GAIN, DIFFUSE_GAIN, FLUENCE_GAIN,
    # AMBIENT_GAIN, GROUND_LIGHT_GAIN, as the Rust source has them.
    shipped = np.array(shipped_gains(SIX))
    show("shipped", data, shipped)
    X = np.concatenate([np.einsum("nck,c->nk", p, Y) / (t @ Y)[:, None]
                        for t, z, p in data.values()])
    yv = np.concatenate([((t - z) @ Y) / (t @ Y) for t, z, p in data.values()])
    g_ls, *_ = np.linalg.lstsq(X, yv, rcond=None)
    show("least squares", data, g_ls)
    nm = {"maxiter": 4000, "xatol": 1e-4, "fatol": 1e-6}
    # A gain shipped at 0 starts at 1: Nelder-Mead's first simplex around
    # 0 is too small to leave it.
    start = np.where(shipped == 0, 1.0, shipped)
    fit = minimize(lambda g: sum(s[0] for s in scores(data, np.abs(g))), start,
                   method="Nelder-Mead", options=nm)
    show("per-pixel errors", data, np.abs(fit.x))
    w = a.colour_weight

    def gains(g):
        g = np.abs(g)
        for i, v in held.items():
            g[i] = v
        return g

    def objective(g):
        total = 0.0
        for e, _, tops, rb in scores(data, gains(g)):
            total += e + w * abs(np.log(rb))
            if a.tops_band is not None:
                total += 5 * max(0.0, abs(tops - 1) - a.tops_band)
        return total

    fit = minimize(objective, start, method="Nelder-Mead", options=nm)
    # Powell from there: Nelder-Mead stalls in six dimensions.
    fit = minimize(objective, np.abs(fit.x), method="Powell", options={"maxiter": 20000})
    label = f"per-pixel errors and colour (weight {w})"
    if a.tops_band is not None:
        label += f", tops within {a.tops_band}"
    if held:
        label += ", held " + " ".join(a.hold)
    show(label, data, gains(fit.x))


if __name__ == "__main__":
    main()
