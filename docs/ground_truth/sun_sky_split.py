#!/usr/bin/env python3
"""Splits one view's light into the sun's part and the sky's, ours and
the path tracer's, and asks how far each part's error goes: the
per-pixel error were either part exact, by bins of angle and depth, and
two candidate fixes measured as bounds (a gain per bin of the sun's
optical depth on the sun's multiply scattered light; the sky's light
scattered from 32 directions with the phase function, each dimmed by
the cloud toward it).

    docs/ground_truth/gain_parts.sh /tmp/parts
    python3 docs/ground_truth/compare.py --width 80 --height 60 --spp 4096 --cells 1024 \\
        --supersample 4 --cache /tmp/gt --views backlit
    python3 docs/ground_truth/sun_sky_split.py --view backlit --parts /tmp/parts \\
        --cache /tmp/gt [--sky-model]

The path tracer's sun part is Mitsuba's render with the sun alone
(`compare.mitsuba_render(..., sky=False)`, all orders; rendered into
--cache at --sun-spp when absent, 6 minutes at 1024 on 2 cores), its sky
part the full render's remainder. Ours: gain_parts.sh's builds rendered
as fit_gains.py renders them (cached in --fitcache), plus the zero build
with --single-scattering; the sun part is the single scattering, the
octaves, the diffused light and the light volume at the shipped gains,
the sky part the background through the clouds and the sky's and the
ground's light. --sky-model marches the exported grid as surrogate.py
does (about 10 minutes a view here) for the sample-weighted optical
depth toward the sun of each pixel and for the directional sky term.
Mitsuba's sun-only render has its own noise (about 5 % per pixel at
1024 samples), which the "exact" rows carry.
"""

import argparse
import glob
import json
import os
import re
import sys
import tempfile

import numpy as np
from scipy.ndimage import map_coordinates
from scipy.optimize import minimize

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import compare as C  # noqa: E402
import fit_gains as F  # noqa: E402
import surrogate as S  # noqa: E402

Y = np.array([0.2126, 0.7152, 0.0722])
SUN_PARTS = ["mf", "mi", "di", "fl"]
SKY_PARTS = ["am", "gr"]


def shipped():
    """The six gains as the renderer ships them."""
    g = {}
    names = {"mf": "MULTIPLE_GAIN", "mi": "MULTIPLE_ISOTROPIC_GAIN", "di": "DIFFUSE_GAIN",
             "fl": "FLUENCE_GAIN", "am": "AMBIENT_GAIN", "gr": "GROUND_LIGHT_GAIN"}
    text = "".join(open(os.path.join(C.ROOT, f)).read()
                   for f in ("src/render/cpu/lighting.rs", "src/render/cpu/renderer.rs"))
    for k, name in names.items():
        g[k] = float(re.search(rf"pub const {name}: f32 = ([0-9.]+);", text).group(1))
    return g


def ours_single(binary, view, width, height, ss, cache):
    """Our single scattering (no sky, no background), 4x supersampled."""
    st = os.stat(binary)
    path = os.path.join(cache, f"{view}_single_{st.st_size}_{int(st.st_mtime)}_{width}x{height}x{ss}.npy")
    if os.path.exists(path):
        return np.load(path)
    _, base, el, az, yaw = next(v for v in C.VIEWS if v[0] == view)
    scene = os.path.join(C.ROOT, "scenes", f".split_{view}_{os.getpid()}.toml")
    C.scene_variant(base, el, az, yaw, width * ss, height * ss, scene, C.VIEW_CAMERA.get(view, {}))
    with tempfile.TemporaryDirectory() as tmp:
        exr = os.path.join(tmp, "s.exr")
        try:
            C.run([binary, "render", "--scene", scene, "--backend", "cpu", "--single-scattering",
                   "--out", exr])
        finally:
            os.remove(scene)
        img = C.read_exr(exr).reshape(height, ss, width, ss, 3).mean(axis=(1, 3))
    C.save_cached(path, img)
    return img


def fib(n):
    """`n` directions spread evenly over the sphere (y up)."""
    i = np.arange(n) + 0.5
    y = 1 - 2 * i / n
    r = np.sqrt(1 - y * y)
    return np.stack([r * np.cos(2.399963 * i), y, r * np.sin(2.399963 * i)], 1)


def sky_samples(view, binary, width, height, cells, k_dirs=32):
    """surrogate.py's cloud samples of the view, each with its optical
    depth toward `k_dirs` directions through the grid averaged to 8x
    coarser cells (the light volume's 80 m) over 2.5 km, and the
    environment map's radiance in each direction's bin, weighted by the
    phase function toward each pixel's eye."""
    _, base, el, az, yaw = next(v for v in C.VIEWS if v[0] == view)
    with tempfile.TemporaryDirectory() as tmp:
        scene = os.path.join(C.ROOT, "scenes", f".split_{view}_{os.getpid()}.toml")
        C.scene_variant(base, el, az, yaw, width, height, scene, C.VIEW_CAMERA.get(view, {}))
        vol, sky = os.path.join(tmp, "v.vol"), os.path.join(tmp, "v_sky.exr")
        try:
            C.run([binary, "export", "--scene", scene, "--out", vol, "--sky", sky,
                   "--cells", str(cells)])
        finally:
            os.remove(scene)
        side = json.load(open(vol[:-4] + ".json"))
        grid = C.read_vol(vol).astype(np.float32)
        s = S.march_samples(side, grid, width, height)
        s["bg"], s["up"], s["up_cos"], s["down"] = S.sky_terms(side, sky, width, height)
        env = C.read_exr(sky)
    lo, hi = np.array(side["box_min_m"]), np.array(side["box_max_m"])
    nz, ny, nx = grid.shape
    f, fy = 8, max(ny // 8, 1)
    coarse = grid[:nz // f * f, :fy * 8, :nx // f * f].reshape(nz // f, f, fy, 8, nx // f, f).mean(axis=(1, 3, 5))
    h = (hi - lo) / np.array([nx // f, fy, nz // f]) * np.array([1, ny / (fy * 8), 1])
    dirs = fib(k_dirs)
    P = s["P"]

    def depth(d, length=2500.0, step=40.0):
        acc = np.zeros(len(P), np.float32)
        for j in range(int(length / step)):
            q = P + d * (j + 0.5) * step
            g = (q - lo) / h - 0.5
            inside = (q[:, 1] >= lo[1]) & (q[:, 1] <= hi[1])
            acc += map_coordinates(coarse, [g[:, 2], g[:, 1], g[:, 0]], order=1,
                                   mode="grid-wrap") * step * inside
        return acc

    s["taus"] = np.stack([depth(d) for d in dirs], 1)
    eh, ew = env.shape[:2]
    jj, ii = np.meshgrid(np.arange(eh), np.arange(ew), indexing="ij")
    phi, th = (ii + 0.5) / ew * 2 * np.pi, (jj + 0.5) / eh * np.pi
    ed = np.stack([np.sin(th) * np.sin(phi), np.cos(th), -np.sin(th) * np.cos(phi)], -1).reshape(-1, 3)
    radiance = (env.reshape(-1, 3) @ Y) * (np.sin(th) * np.pi / eh * 2 * np.pi / ew).reshape(-1)
    in_bin = np.argmax(ed @ dirs.T, axis=1)
    s["LO"] = np.bincount(in_bin, radiance, k_dirs)
    _, view_dirs = C.camera_rays(side, width, height)
    view_dirs = view_dirs.reshape(-1, 3)
    A = np.zeros((width * height, k_dirs))
    for c0 in range(0, width * height, 200):
        ph = S.dual(view_dirs[c0:c0 + 200] @ ed.T, 1.0) * radiance
        for k in range(k_dirs):
            A[c0:c0 + 200, k] = ph[:, in_bin == k].sum(1)
    s["A"] = A
    s["eta"] = np.clip((s["y"] - lo[1]) / (hi[1] - lo[1]), 0, 1)
    return s


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--view", default="backlit")
    ap.add_argument("--parts", required=True, help="gain_parts.sh's output folder")
    ap.add_argument("--cache", required=True, help="compare.py's --cache (Mitsuba's renders)")
    ap.add_argument("--fitcache", default="/tmp/fitcache", help="our renders, as fit_gains.py keeps them")
    ap.add_argument("--spp", type=int, default=4096, help="the full reference's samples")
    ap.add_argument("--sun-spp", type=int, default=1024, help="the sun-only reference's samples")
    ap.add_argument("--cells", type=int, default=1024)
    ap.add_argument("--sky-model", action="store_true",
                    help="also the sun-depth bins and the directional sky (marches the grid)")
    ap.add_argument("--bin", default=os.path.join(C.ROOT, "target/release/cumulus"))
    a = ap.parse_args()
    W, H, SS = 80, 60, 4
    v = a.view
    full = C.cache_key(v, W, H, a.spp, a.cells)
    if not os.path.exists(os.path.join(a.cache, full)):
        sys.exit(f"{a.cache}/{full}: no reference; run compare.py with --cache first")
    m = np.load(os.path.join(a.cache, full)) @ Y
    sun_ref = os.path.join(a.cache, C.cache_key(v, W, H, a.sun_spp, a.cells, "_sun"))
    vol_tmp = tempfile.TemporaryDirectory()
    _, base, el, az, yaw = next(x for x in C.VIEWS if x[0] == v)
    scene = os.path.join(C.ROOT, "scenes", f".split_{v}_{os.getpid()}.toml")
    C.scene_variant(base, el, az, yaw, W, H, scene, C.VIEW_CAMERA.get(v, {}))
    vol, sky = os.path.join(vol_tmp.name, "v.vol"), os.path.join(vol_tmp.name, "v_sky.exr")
    try:
        C.run([a.bin, "export", "--scene", scene, "--out", vol, "--sky", sky, "--cells", str(a.cells)])
    finally:
        os.remove(scene)
    side = json.load(open(vol[:-4] + ".json"))
    if not os.path.exists(sun_ref):
        print(f"rendering the sun alone at {a.sun_spp} samples ...", flush=True)
        C.save_cached(sun_ref, C.mitsuba_render(vol, sky, side, a.sun_spp, W, H, sky=False))
    msun = np.load(sun_ref) @ Y
    msky = m - msun
    cloud, tau, _ = C.cloud_pixels(v, vol, side, W, H)
    _, dirs = C.camera_rays(side, W, H)
    sun = np.array(side["sun_direction"]) / np.linalg.norm(side["sun_direction"])
    ang = np.degrees(np.arccos(np.clip(dirs @ sun, -1, 1))).reshape(H, W)
    vol_tmp.cleanup()

    fa = argparse.Namespace(cache=a.fitcache, width=W, height=H, supersample=SS)
    with tempfile.TemporaryDirectory() as tmp:
        P = {k: F.cached_render(fa, os.path.join(a.parts, f"cumulus_{k}"), v, {}, tmp) @ Y
             for k in ["zero"] + SUN_PARTS + SKY_PARTS}
    single = ours_single(os.path.join(a.parts, "cumulus_zero"), v, W, H, SS, a.fitcache) @ Y
    g = shipped()
    osun = single + sum(g[k] * (P[k] - P["zero"]) for k in SUN_PARTS)
    osky = (P["zero"] - single) + sum(g[k] * (P[k] - P["zero"]) for k in SKY_PARTS)
    ours = osun + osky

    def err(x):
        return (np.abs(x - m) / m)[cloud].mean()

    print(f"{v}: {cloud.sum()} cloud pixels; Mitsuba {a.spp} samples, its sun alone {a.sun_spp}")
    print(f"  per-pixel error as shipped          {err(ours):.4f}")
    print(f"  were our sun part Mitsuba's         {err(msun + osky):.4f}")
    print(f"  were our sky part Mitsuba's         {err(osun + msky):.4f}")
    print(f"  the sun's share of the light: Mitsuba {msun[cloud].sum() / m[cloud].sum():.3f}, "
          f"ours {osun[cloud].sum() / ours[cloud].sum():.3f}")
    X = np.stack([P[k] - P["zero"] for k in SUN_PARTS], -1)
    r = minimize(lambda x: err(single + X @ x + msky), [g[k] for k in SUN_PARTS], method="Nelder-Mead",
                 options=dict(maxiter=3000))
    print(f"  the sun's four gains refitted with the sky part Mitsuba's: {err(single + X @ r.x + msky):.4f} "
          f"(gains {' '.join(f'{x:.2f}' for x in r.x)})")
    print("  Mitsuba over ours, by angle to the sun and the view's optical depth:")
    for lo_a, hi_a in [(0, 15), (15, 35), (35, 90)]:
        for lo_t, hi_t in [(1, 3), (3, 10), (10, np.inf)]:
            k = cloud & (ang >= lo_a) & (ang < hi_a) & (tau >= lo_t) & (tau < hi_t)
            if k.sum() < 10:
                continue
            print(f"    {lo_a:2d}-{hi_a:2d}°, depth {lo_t:2d}-{hi_t:<4}: {k.sum():5d} px, error "
                  f"{(np.abs(ours - m) / m)[k].mean():.3f}; sun {msun[k].sum() / osun[k].sum():.3f}, "
                  f"sky {msky[k].sum() / osky[k].sum():.3f}; sun's share Mitsuba "
                  f"{msun[k].sum() / m[k].sum():.2f}, ours {osun[k].sum() / ours[k].sum():.2f}")
    if not a.sky_model:
        return

    s = sky_samples(v, a.bin, W, H, a.cells)
    n = W * H
    w = s["w"] * S.ALBEDO

    def pixsum(f):
        return np.bincount(s["pix"], w * f, n).reshape(H, W)

    wsum = pixsum(np.ones_like(w))
    tau_sun = pixsum(s["tau_sun"]) / np.maximum(wsum, 1e-9)
    mult = osun - single
    edges = np.array([0, 2, 4, 6, 8, 10, 13, 17, np.inf])
    b = np.digitize(tau_sun, edges) - 1
    print("  Mitsuba over ours, the sun's part, by the sample-weighted optical depth toward the sun:")
    fixed = osun.copy()
    for i in range(len(edges) - 1):
        k = cloud & (b == i)
        if k.sum() < 10:
            continue
        best = min(np.linspace(0.3, 3, 271),
                   key=lambda x: (np.abs(single[k] + x * mult[k] + msky[k] - m[k]) / m[k]).sum())
        fixed[k] = single[k] + best * mult[k]
        print(f"    {edges[i]:4.0f}-{edges[i + 1]:<4}: {k.sum():5d} px, sun {msun[k].sum() / osun[k].sum():.3f}; "
              f"best gain on its multiply scattered light {best:.2f}")
    print(f"  that gain per bin, the sky part Mitsuba's: {err(fixed + msky):.4f}")
    terms = {
        "the shipped sky and ground profiles": [
            pixsum(s["up_cos"] / 4 * (0.35 + 0.65 * s["eta"])), pixsum(s["down"] / 4 * (1 - s["eta"]))],
    }
    direct = pixsum((s["A"][s["pix"]] * np.exp(-s["taus"])).sum(1))
    terms["+ the sky scattered from 32 directions, each dimmed by the cloud toward it"] = \
        terms["the shipped sky and ground profiles"] + [direct]
    background = P["zero"] - single  # ours: the sky seen through the clouds
    print("  the sky part modelled on the exported grid, its gains fitted, the sun part Mitsuba's:")
    for label, cols in terms.items():
        Xs = np.stack(cols, -1)
        x0, *_ = np.linalg.lstsq((Xs[cloud] / m[cloud, None]), ((msky - background) / m)[cloud], rcond=None)
        r = minimize(lambda x: err(msun + background + Xs @ x), x0, method="Nelder-Mead",
                     options=dict(maxiter=4000))
        print(f"    {label}: {r.fun:.4f} (gains {' '.join(f'{x:.2f}' for x in r.x)})")
    joint = [X, np.stack(terms[list(terms)[1]], -1)]
    Xj = np.concatenate(joint, -1)
    base = single + background
    x0, *_ = np.linalg.lstsq(Xj[cloud] / m[cloud, None], ((m - base) / m)[cloud], rcond=None)
    r = minimize(lambda x: err(base + Xj @ x), x0, method="Powell", options=dict(maxiter=20000))
    print(f"  our sun parts and that sky, all gains fitted on this view: {r.fun:.4f}")


if __name__ == "__main__":
    main()
