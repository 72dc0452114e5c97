#!/usr/bin/env bash
# The sun's light scattered once, ours against Mitsuba limited to one
# scattering (compare.py --single-scattering), for several shadow-ray
# step counts: how far the shadow ray's transmittance is from the path
# tracer's. Writes single_scattering.csv and the side-by-side pictures of
# the default (20 steps) here. Mitsuba renders once per view (cached in
# $CACHE, default /tmp/gt_single); each step count then takes a minute.
set -euo pipefail
HERE="$(cd "$(dirname "$0")" && pwd)"
CACHE="${CACHE:-/tmp/gt_single}"
SPP="${SPP:-1024}"
STEPS="${STEPS:-12 20 32 48 64}"
mkdir -p "$CACHE"
OUT="$(mktemp -d)"
trap 'rm -rf "$OUT"' EXIT
for n in $STEPS; do
  mkdir -p "$OUT/$n"
  python3 "$HERE/compare.py" --width 80 --height 60 --spp "$SPP" --cells 512 --supersample 4 \
    --single-scattering --set "shadow_steps=$n" --cache "$CACHE" --out "$OUT/$n" \
    --views high_sun,low_sun,backlit
done
python3 - "$OUT" "$HERE" $STEPS <<'PY'
import csv, os, shutil, sys
out, here, steps = sys.argv[1], sys.argv[2], sys.argv[3:]
rows = []
for n in steps:
    for r in csv.DictReader(open(os.path.join(out, n, "ground_truth.csv"))):
        rows.append({"shadow_steps": n, **r})
tmp = os.path.join(here, ".single_scattering.csv.tmp")
with open(tmp, "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=list(rows[0]))
    w.writeheader()
    w.writerows(rows)
os.replace(tmp, os.path.join(here, "single_scattering.csv"))
if "20" in steps:
    for v in ("high_sun", "low_sun", "backlit"):
        src = os.path.join(out, "20", f"{v}_side_by_side.png")
        if os.path.exists(src):
            shutil.copy(src, os.path.join(here, f"{v}_single_side_by_side.png"))
PY
echo "wrote $HERE/single_scattering.csv"
