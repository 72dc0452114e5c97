#!/usr/bin/env bash
# Regenerates every figure and table under docs/ with the binary, from the
# repository root, and rewrites the docs' tables of numbers from them
# (docs/doc_tables.py: README.md, docs/physics.md, docs/renderer.md).
#
#   docs/regenerate.sh            the deterministic ones: the gallery, the
#                                 render-quality and convergence reports,
#                                 the field statistics, docs/scene.md's
#                                 check (a few minutes on 2 cores)
#   docs/regenerate.sh --all      also the sky-demo screenshot (needs
#                                 xvfb-run) and the GPU benchmarks (long on
#                                 lavapipe; name the device in
#                                 docs/benchmarks.md when you paste them)
#
# The committed numbers are checked against the code by tests
# (tests/docs_numbers.rs: the statistics tables, the error columns of
# docs/render_quality/render_quality.csv and
# docs/convergence/convergence.csv, and the doc tables made from them);
# wall-clock columns depend on the machine and are not checked.
set -euo pipefail
cd "$(dirname "$0")/.."

all=false
case "${1:-}" in
  --all) all=true ;;
  "") ;;
  *) echo "usage: docs/regenerate.sh [--all]" >&2; exit 2 ;;
esac

cargo build --release --bin cumulus --example sky
bin=target/release/cumulus

echo "== gallery (README 'Gallery')"
for s in fair_weather bomex evening strong_inversion \
  view_high_flight view_backlit view_below_base view_horizon automaton spheroids endless; do
  "$bin" render --scene "scenes/$s.toml" --out "docs/$s.png"
done

echo "== render quality (docs/renderer.md 'Error against cost (rendering)')"
"$bin" render --scene scenes/fair_weather.toml --quality-report docs/render_quality

echo "== convergence (docs/physics.md 'Error against run time (physics)')"
"$bin" convergence --scene scenes/bomex.toml --out docs/convergence

echo "== field statistics (README and docs/physics.md 'Cloud-field statistics')"
stats=$(mktemp -d)
trap 'rm -rf "$stats"' EXIT
for s in fair_weather bomex; do
  "$bin" stats --scene "scenes/$s.toml" --out "$stats/$s" | tee "$stats/$s.txt"
done

echo "== the docs' tables from the files above"
python3 docs/doc_tables.py "$stats"

if $all; then
  echo "== sky demo screenshot (README 'The sky demo')"
  xvfb-run -a -s "-screen 0 1600x900x24" target/release/examples/sky \
    --screenshot docs/sky_demo.png --frames 32
  echo "== GPU benchmarks (docs/benchmarks.md, docs/bench)"
  "$bin" bench --out docs/bench
fi

echo "== checking the committed numbers against the code"
cargo test --release --test docs_numbers --test scene_docs
echo "Now look at every picture, read the text around the docs' tables"
echo "(it may quote a number that moved), and commit."
