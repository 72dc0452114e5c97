#!/usr/bin/env python3
"""The path tracer's own noise, as the per-pixel error compare.py reports:
Mitsuba renders each view twice with different seeds, and the two are
compared with compare.py's measure (mean |relative luminance error| on
cloud pixels, per pixel and on 4x4 blocks, and the ratio of the 99th
percentiles). A noise-free renderer compared with one such render cannot
score much below this floor divided by √2.

    python3 docs/ground_truth/noise_floor.py [--width 80] [--height 60] [--spp 64]

With `--ours DIR` (compare.py's `--arrays` output, same size and sample
count) it also scores our render against each of the two and against
their mean, and estimates our error against a noise-free reference by
taking the reference's noise out in quadrature (exact for independent
Gaussian errors; where our error is a systematic offset it reads low,
0.85 of an offset as large as the noise). With compare.py's `--cache` and
`--cells`, the first render is compare.py's own:

    python3 docs/ground_truth/noise_floor.py --spp 1024 --cells 1024 --cache /tmp/gt \\
        --seed-offset 5000 --views high_sun,side --ours /tmp/gt/arrays

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
    ap.add_argument("--cells", type=int, default=None,
                    help="the exported grid's cells (compare.py's --cells; default the export's)")
    ap.add_argument("--bin", default=os.path.join(C.ROOT, "target/release/cumulus"))
    ap.add_argument("--views", default=",".join(v[0] for v in C.VIEWS))
    ap.add_argument("--seed-offset", type=int, default=1000,
                    help="the second render's seeds start here (the first's at 0)")
    ap.add_argument("--cache", default=None,
                    help="compare.py's --cache (needs --cells): the first render is compare.py's "
                         "own when there (this script never writes that one), the second is "
                         "read from or kept beside it under a name with its seeds")
    ap.add_argument("--ours", default=None,
                    help="compare.py --arrays output (VIEW_ours.npy): score ours against both")
    a = ap.parse_args()
    if a.cache and not a.cells:
        sys.exit("--cache: give --cells as well (compare.py's cache names its grid)")
    # Each render is passes of 16 samples seeded 0, 1, ... (compare.py's
    # mitsuba_render): the second's seeds must not reach into the first's.
    passes = max(1, (a.spp + 15) // 16)
    if a.seed_offset < passes:
        sys.exit(f"--seed-offset {a.seed_offset}: at least {passes} at {a.spp} samples, "
                 "or the two renders share seeds")
    import mitsuba as mi

    mi.set_variant("llvm_ad_rgb")
    render = mi.render
    with tempfile.TemporaryDirectory() as tmp:
        for name, base, el, az, yaw in [v for v in C.VIEWS if v[0] in a.views.split(",")]:
            scene = os.path.join(C.ROOT, "scenes", f".floor_{name}.toml")
            C.scene_variant(base, el, az, yaw, a.width, a.height, scene, C.VIEW_CAMERA.get(name, {}))
            vol, sky = os.path.join(tmp, f"{name}.vol"), os.path.join(tmp, f"{name}_sky.exr")
            try:
                cells = ["--cells", str(a.cells)] if a.cells else []
                subprocess.run([a.bin, "export", "--scene", scene, "--out", vol, "--sky", sky] + cells,
                               check=True, capture_output=True)
            finally:
                os.remove(scene)
            side = json.load(open(vol[:-4] + ".json"))
            renders = []
            for offset in (0, a.seed_offset):
                # compare.py's cache key; the second render's names its seeds.
                key = C.cache_key(name, a.width, a.height, a.spp, a.cells,
                                  f"_seed{offset}" if offset else "")
                cached = os.path.join(a.cache, key) if a.cache and a.cells else None
                if cached and os.path.exists(cached):
                    renders.append(np.load(cached))
                    continue
                mi.render = lambda s, spp=None, seed=0, **k: render(s, spp=spp, seed=seed + offset, **k)
                renders.append(C.mitsuba_render(vol, sky, side, a.spp, a.width, a.height))
                mi.render = render
                if cached and offset:
                    C.save_cached(cached, renders[-1])
            cloud = C.cloud_pixels(name, vol, side, a.width, a.height)[0]
            y1, y2 = C.luminance(renders[1]), C.luminance(renders[0])
            rel = (y1 - y2) / np.maximum(y2, 1e-6)
            bh, bw = a.height // 4, a.width // 4
            blocks = lambda x: x[:bh * 4, :bw * 4].reshape(bh, 4, bw, 4).mean(axis=(1, 3))
            full = blocks(cloud.astype(float)) == 1.0
            rb = (blocks(y1) - blocks(y2)) / np.maximum(blocks(y2), 1e-6)
            tops = np.percentile(y1[cloud], 99) / np.percentile(y2[cloud], 99)
            print(f"{name}: Mitsuba against Mitsuba, mean |rel. error| {np.abs(rel[cloud]).mean():.3f} "
                  f"(4x4 blocks {np.abs(rb[full]).mean():.3f}), tops {tops:.3f}", flush=True)
            if a.ours:
                ours = C.luminance(np.load(os.path.join(a.ours, f"{name}_ours.npy")))
                floor = float(np.abs(rel[cloud]).mean()) / np.sqrt(2)  # one render's noise
                refs = (("seeds from 0", y2, floor), (f"seeds from {a.seed_offset}", y1, floor),
                        ("their mean", (y1 + y2) / 2, floor / np.sqrt(2)))
                for label, ref, noise in refs:
                    e = float(np.abs((ours - ref) / np.maximum(ref, 1e-6))[cloud].mean())
                    clean = np.sqrt(max(e * e - noise * noise, 0.0))
                    print(f"  ours against {label}: {e:.3f}; its noise {noise:.3f}, "
                          f"so against a noise-free reference about {clean:.3f}", flush=True)


if __name__ == "__main__":
    main()
