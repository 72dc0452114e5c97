#!/usr/bin/env python3
"""The path tracer's own noise, as the per-pixel error compare.py reports:
Mitsuba renders each view twice with different seeds, and the two are
compared with compare.py's measure (mean |relative luminance error| on
cloud pixels, per pixel and on 4x4 blocks, and the ratio of the 99th
percentiles). A noise-free renderer compared with one such render cannot
score much below this floor divided by √2.

    python3 docs/ground_truth/noise_floor.py [--width 80] [--height 60] [--spp 64]

Same setup as compare.py (Mitsuba 3.9.1, DRJIT_LIBLLVM_PATH on Debian 12).
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import compare as C  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--width", type=int, default=80)
    ap.add_argument("--height", type=int, default=60)
    ap.add_argument("--bin", default=os.path.join(C.ROOT, "target/release/cumulus"))
    a = ap.parse_args()
    import mitsuba as mi

    mi.set_variant("llvm_ad_rgb")
    render = mi.render
    with tempfile.TemporaryDirectory() as tmp:
        for name, base, el, az, yaw in C.VIEWS:
            scene = os.path.join(C.ROOT, "scenes", f".floor_{name}.toml")
            C.scene_variant(base, el, az, yaw, a.width, a.height, scene, C.VIEW_CAMERA.get(name, {}))
            vol, sky = os.path.join(tmp, f"{name}.vol"), os.path.join(tmp, f"{name}_sky.exr")
            try:
                subprocess.run([a.bin, "export", "--scene", scene, "--out", vol, "--sky", sky],
                               check=True, capture_output=True)
            finally:
                os.remove(scene)
            side = json.load(open(vol[:-4] + ".json"))
            renders = []
            for offset in (0, 1000):
                mi.render = lambda s, spp=None, seed=0, **k: render(s, spp=spp, seed=seed + offset, **k)
                renders.append(C.mitsuba_render(vol, sky, side, a.spp, a.width, a.height))
            mi.render = render
            eye, dirs = C.camera_rays(side, a.width, a.height)
            cloud = C.optical_depth(C.read_vol(vol), side, eye, dirs) >= C.VIEW_TAU_MIN.get(name, 1.0)
            y1, y2 = C.luminance(renders[1]), C.luminance(renders[0])
            rel = (y1 - y2) / np.maximum(y2, 1e-6)
            bh, bw = a.height // 4, a.width // 4
            blocks = lambda x: x[:bh * 4, :bw * 4].reshape(bh, 4, bw, 4).mean(axis=(1, 3))
            full = blocks(cloud.astype(float)) == 1.0
            rb = (blocks(y1) - blocks(y2)) / np.maximum(blocks(y2), 1e-6)
            tops = np.percentile(y1[cloud], 99) / np.percentile(y2[cloud], 99)
            print(f"{name}: Mitsuba against Mitsuba, mean |rel. error| {np.abs(rel[cloud]).mean():.3f} "
                  f"(4x4 blocks {np.abs(rb[full]).mean():.3f}), tops {tops:.3f}", flush=True)


if __name__ == "__main__":
    main()
