#!/usr/bin/env bash
# Side by side on one machine: the density reads per pixel and the GPU
# frame time of three views, for the shadow rays' whole march (a build
# from before the light volume's sun depth, OLD, and this build with the
# light volume off) and the near march plus the volume's depth (this
# build). The figures in docs/benchmarks.md, "Reads per pixel", come
# from it (lavapipe on the 2-core machine).
#
#   docs/shadow_depth_bench.sh OLD_BINARY [NEW_BINARY] > out.txt
set -euo pipefail
old=${1:?usage: docs/shadow_depth_bench.sh OLD_BINARY [NEW_BINARY]}
new=${2:-target/release/cumulus}
png=$(mktemp --suffix=.png)
trap 'rm -f "$png"' EXIT
for v in fair_weather view_backlit view_high_flight; do
  for size in "320 240" "640 480"; do
    set -- $size
    # The command: 16 photons a column (the build's time is not
    # the frame's), one frame, then three timed after ten of warm-up.
    args=(render --scene "scenes/$v.toml" --backend gpu --width "$1" --height "$2"
          --frames 1 --time-frames 3 --out "$png")
    if [ "$1" = 320 ]; then
      echo "== $v $1x$2 whole shadow ray (old build)"
      "$old" "${args[@]}" --light-photons 16 2>/dev/null | grep -E "^frame|clouds:"
    fi
    echo "== $v $1x$2 whole shadow ray (no light volume)"
    "$new" "${args[@]}" --light-photons 0 2>/dev/null | grep -E "^frame|clouds:|reads"
    echo "== $v $1x$2 near march + the volume's depth"
    "$new" "${args[@]}" --light-photons 16 2>/dev/null | grep -E "^frame|clouds:|reads"
  done
done
