#!/usr/bin/env python3
"""The flat land under the clouds against a path tracer: in the sun and
in the clouds' shadows.

Mitsuba 3 path-traces the volume `cumulus export` writes over a Lambertian
plane of the land's albedo (`LAND_ALBEDO`, render/cpu/sky.rs), lit by the
same sun and sky (compare.py's scene plus the plane); ours is `cumulus
render --backend cpu` of the same view with no aerial perspective. The
camera stands 400 m up in the middle of the fair-weather domain, under
the cloud base, looking down at 35°, so every pixel is ground within
~1.5 km and every shadow ray toward the sun stays inside the exported box.

Pixels are split by the optical depth toward the sun from their ground
point through the exported grid (marched here, apart from both
renderers): sunlit (under 0.05) and shadowed (over 3). Printed per view:
each class's mean luminance, ours and Mitsuba's, their ratio, and the
shadow's red over blue; `ground_shadow.csv` holds them, and
`ground_shadow_bins.csv` the land's irradiance over π (luminance over the
albedo's) per bin of that optical depth.

    python3 docs/ground_truth/ground_shadow.py [--spp 256] [--cache DIR]
"""

import argparse
import csv
import json
import os
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import compare  # noqa: E402

# (name, sun elevation, sun azimuth, camera yaw)
VIEWS = [
    ("ground_high_sun", 60.0, 110.0, 20.0),
    ("ground_mid_sun", 30.0, 110.0, 20.0),
]
CAMERA = {"camera_position_m": "[5000.0, 400.0, 5000.0]", "camera_pitch_deg": "-35.0"}
LAND_ALBEDO = (0.08, 0.10, 0.06)
TAU_BINS = [0.0, 0.05, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 1e9]


def sun_depth(vol, side, eye, dirs, steps=300):
    """Optical depth from each pixel's ground point toward the sun through
    the exported grid (nearest cell, uniform steps to the box's top)."""
    lo, hi = np.array(side["box_min_m"]), np.array(side["box_max_m"])
    res = np.array(side["resolution"])
    sun = np.array(side["sun_direction"]) / np.linalg.norm(side["sun_direction"])
    ground = eye + dirs * (eye[1] / -dirs[..., 1])[..., None]
    length = hi[1] / sun[1]
    tau = np.zeros(dirs.shape[:2])
    for k in range(steps):
        p = ground + sun * ((k + 0.5) / steps * length)
        idx = np.floor((p - lo) / (hi - lo) * res).astype(int)
        inside = np.all((idx >= 0) & (idx < res), axis=2)
        i = np.clip(idx, 0, res - 1)
        tau += np.where(inside, vol[i[..., 2], i[..., 1], i[..., 0]] * length / steps, 0)
    return tau


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--width", type=int, default=80)
    ap.add_argument("--height", type=int, default=60)
    ap.add_argument("--cells", type=int, default=512)
    ap.add_argument("--bin", default=os.path.join(compare.ROOT, "target/release/cumulus"))
    ap.add_argument("--out", default=compare.HERE)
    ap.add_argument("--cache", default=None, help="keep Mitsuba's renders here")
    a = ap.parse_args()
    rows, bins = [], []
    with tempfile.TemporaryDirectory() as tmp:
        for name, sun_el, sun_az, yaw in VIEWS:
            scene = os.path.join(compare.ROOT, "scenes", f".gs_{name}_{os.getpid()}.toml")
            compare.scene_variant("fair_weather", sun_el, sun_az, yaw, a.width, a.height,
                                  scene, CAMERA)
            try:
                vol = os.path.join(tmp, f"{name}.vol")
                sky = os.path.join(tmp, f"{name}_sky.exr")
                ours_path = os.path.join(tmp, f"{name}_ours.exr")
                compare.run([a.bin, "export", "--scene", scene, "--out", vol, "--sky", sky,
                             "--cells", str(a.cells)])
                compare.run([a.bin, "render", "--scene", scene, "--backend", "cpu",
                             "--out", ours_path])
            finally:
                os.remove(scene)
            side = json.load(open(vol[:-4] + ".json"))
            ours = compare.read_exr(ours_path)
            key = compare.cache_key(name, a.width, a.height, a.spp, a.cells)
            cached = os.path.join(a.cache, key) if a.cache else None
            if cached and os.path.exists(cached):
                mi_img = np.load(cached)
            else:
                mi_img = compare.mitsuba_render(vol, sky, side, a.spp, a.width, a.height,
                                                ground=LAND_ALBEDO)
                if cached:
                    compare.save_cached(cached, mi_img)
            eye, dirs = compare.camera_rays(side, a.width, a.height)
            tau = sun_depth(compare.read_vol(vol), side, eye, dirs)
            y_ours, y_mi = compare.luminance(ours), compare.luminance(mi_img)
            row = {"view": name, "sun_elevation_deg": sun_el}
            for cls, mask in [("sunlit", tau < 0.05), ("shadow", tau > 3.0)]:
                n = int(mask.sum())
                mo, mm = (float(y_ours[mask].mean()), float(y_mi[mask].mean())) if n else (0, 0)
                row[f"{cls}_pixels"] = n
                row[f"{cls}_ours"] = round(mo, 5)
                row[f"{cls}_mitsuba"] = round(mm, 5)
                row[f"{cls}_ratio"] = round(mo / mm, 3) if mm > 0 else ""
                if cls == "shadow" and n:
                    rb = lambda img: float(img[mask][:, 0].mean() / img[mask][:, 2].mean())
                    row["shadow_red_over_blue_ours"] = round(rb(ours), 3)
                    row["shadow_red_over_blue_mitsuba"] = round(rb(mi_img), 3)
            rows.append(row)
            print(row, flush=True)
            # Per bin of the optical depth toward the sun, the luminance
            # over the albedo's (the land's irradiance over π): the path
            # tracer's is sun · f(τ) + diffuse; where f is e^{-τ}, what
            # is left at depth is the diffuse light (sky and clouds).
            albedo = float(compare.luminance(np.array(LAND_ALBEDO)))
            sun = float(compare.luminance(np.array(side["sun_irradiance_rgb"])))
            sun *= np.sin(np.radians(sun_el)) / np.pi
            for lo, hi in zip(TAU_BINS[:-1], TAU_BINS[1:]):
                m = (tau >= lo) & (tau < hi)
                if m.sum() < 10:
                    continue
                bins.append({
                    "view": name, "tau_from": lo, "tau_to": hi, "pixels": int(m.sum()),
                    "mitsuba": round(float(y_mi[m].mean()) / albedo, 4),
                    "ours": round(float(y_ours[m].mean()) / albedo, 4),
                    "exp_minus_tau": round(float(np.exp(-tau[m]).mean()), 4),
                    "sun_mu_over_pi": round(sun, 4),
                })
            strip = np.concatenate([compare.aces(ours, 1.2), compare.aces(mi_img, 1.2)], axis=1)
            from PIL import Image
            Image.fromarray(strip).resize((strip.shape[1] * 4, strip.shape[0] * 4),
                                          Image.NEAREST).save(
                os.path.join(a.out, f"{name}_side_by_side.png"))
    with open(os.path.join(a.out, "ground_shadow.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    with open(os.path.join(a.out, "ground_shadow_bins.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(bins[0].keys()))
        w.writeheader()
        w.writerows(bins)


if __name__ == "__main__":
    main()
