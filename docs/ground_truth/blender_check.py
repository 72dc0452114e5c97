#!/usr/bin/env python3
"""Blender's Cycles on the OpenVDB file `cumulus export` writes, against
Mitsuba 3 on the `.vol` of the same clouds: does a Blender user who
follows the README (README, "Volume export") render the same clouds?

    python3 -m venv /tmp/bpyenv && /tmp/bpyenv/bin/pip install bpy==4.5.15 numpy
    python3 docs/ground_truth/blender_check.py --blender-python /tmp/bpyenv/bin/python \\
        --views high_sun,backlit --spp 512 --cells 1024 --mitsuba-spp 4096 --cache /tmp/gt

Per view (compare.py's views and camera): `cumulus export` writes the
`.vdb`, the `.vol` and the sky; blender_render.py renders the `.vdb` in
Blender (both lobes of the phase function, or with `--phase principled`
the README's one-lobe shortcut); Mitsuba renders the `.vol` (or its
render is read from `--cache`, compare.py's cache, keyed the same way).
On compare.py's cloud pixels: Blender's mean luminance over Mitsuba's,
the mean relative error per pixel and on 4x4 blocks, and the bias.
Writes blender_check.csv and VIEW_blender_side_by_side.png (Blender |
Mitsuba | error, green 0 to red 50 %) into `--out`.
"""

import argparse
import csv
import os
import sys
import tempfile

import numpy as np
from PIL import Image

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import compare as C  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--blender-python", required=True,
                    help="a Python that imports bpy (Blender as a module)")
    ap.add_argument("--views", default="high_sun,backlit")
    ap.add_argument("--width", type=int, default=80)
    ap.add_argument("--height", type=int, default=60)
    ap.add_argument("--spp", type=int, default=512, help="Blender's samples a pixel")
    ap.add_argument("--mitsuba-spp", type=int, default=1024)
    ap.add_argument("--cells", type=int, default=1024)
    ap.add_argument("--phase", choices=["lobes", "principled"], default="lobes")
    ap.add_argument("--bin", default=os.path.join(C.ROOT, "target/release/cumulus"))
    ap.add_argument("--cache", default=None, help="compare.py's cache of Mitsuba's renders")
    ap.add_argument("--out", default=HERE)
    a = ap.parse_args()
    views = [v for v in C.ALL_VIEWS if v[0] in a.views.split(",")]
    if not views:
        sys.exit(f"--views {a.views}: none of {', '.join(v[0] for v in C.ALL_VIEWS)}")
    os.makedirs(a.out, exist_ok=True)
    render_script = os.path.join(HERE, "blender_render.py")
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name, base, sun_el, sun_az, yaw in views:
            scene = os.path.join(C.ROOT, "scenes", f".bl_{name}_{os.getpid()}.toml")
            C.scene_variant(base, sun_el, sun_az, yaw, a.width, a.height, scene,
                            C.VIEW_CAMERA.get(name, {}))
            vol, vdb = os.path.join(tmp, f"{name}.vol"), os.path.join(tmp, f"{name}.vdb")
            sky = os.path.join(tmp, f"{name}_sky.exr")
            exposure = 1.2
            try:
                C.run([a.bin, "export", "--scene", scene, "--out", vol, "--sky", sky,
                       "--cells", str(a.cells)])
                C.run([a.bin, "export", "--scene", scene, "--out", vdb, "--cells", str(a.cells)])
                for line in open(scene):
                    if line.strip().startswith("exposure"):
                        exposure = float(line.split("=")[1].split("#")[0])
            finally:
                os.remove(scene)
            side = C.json.load(open(vol[:-4] + ".json"))
            key = C.cache_key(name, a.width, a.height, a.mitsuba_spp, a.cells)
            cached = os.path.join(a.cache, key) if a.cache else None
            if cached and os.path.exists(cached):
                truth = np.load(cached)
            else:
                truth = C.mitsuba_render(vol, sky, side, a.mitsuba_spp, a.width, a.height)
                if cached:
                    C.save_cached(cached, truth)
            out = os.path.join(tmp, f"{name}_blender")
            C.run([a.blender_python, render_script, vdb, sky, out, str(a.width), str(a.height),
                   str(a.spp), a.phase])
            blender = np.load(out + ".npy")
            cloud, _, _ = C.cloud_pixels(name, vol, side, a.width, a.height)
            yb, ym = C.luminance(blender), C.luminance(truth)
            rel = (yb - ym) / np.maximum(ym, 1e-6)
            bh, bw = a.height // 4, a.width // 4
            blocks = lambda x: x[:bh * 4, :bw * 4].reshape(bh, 4, bw, 4).mean(axis=(1, 3))
            full = blocks(cloud.astype(float)) == 1.0
            rel_b = (blocks(yb) - blocks(ym)) / np.maximum(blocks(ym), 1e-6)
            row = {"view": name, "phase": a.phase, "cloud_pixels": int(cloud.sum()),
                   "luminance_ratio": round(float(yb[cloud].mean() / ym[cloud].mean()), 4),
                   "mean_relative_error": round(float(np.abs(rel[cloud]).mean()), 4),
                   "mean_relative_error_4x4": round(float(np.abs(rel_b[full]).mean()), 4),
                   "bias": round(float(rel[cloud].mean()), 4),
                   "blender_spp": a.spp, "mitsuba_spp": a.mitsuba_spp, "cells": a.cells}
            rows.append(row)
            err = np.clip(np.abs(rel) / 0.5, 0, 1)
            err_img = np.stack([err * 255, (1 - err) * 255 * cloud, np.zeros_like(err)], axis=2)
            err_img = np.where(cloud[..., None], err_img, 0).astype(np.uint8)
            strip = np.concatenate([C.aces(blender, exposure), C.aces(truth, exposure), err_img], axis=1)
            strip = np.repeat(np.repeat(strip, C.FIGURE_SCALE, axis=0), C.FIGURE_SCALE, axis=1)
            Image.fromarray(strip).save(os.path.join(a.out, f"{name}_blender_side_by_side.png"))
            print(name, row, flush=True)
    path = os.path.join(a.out, "blender_check.csv")
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)


if __name__ == "__main__":
    main()
