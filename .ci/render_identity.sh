#!/usr/bin/env bash
# Renders every shipped scene at two commits and compares the PNG bytes: a
# change that claims "behaviour unchanged" (a restructuring) must not move a
# pixel. CPU reference by default; BACKENDS="cpu gpu" also compares the wgpu
# renderer (at 320x240, 8 TSAA frames) on whatever adapter there is.
#
#   .ci/render_identity.sh OLD_COMMIT [NEW_COMMIT]
#
# SIZE=WxH renders every picture at that size (default: the scene's own on
# the CPU, 320x240 on the GPU) and PHOTONS=N traces N light-volume photons
# a column (default: the scene's): SIZE=160x120 PHOTONS=64 checks the same
# code paths on all the shipped scenes in minutes rather than an hour on
# a 2-core machine.
#
# NEW_COMMIT defaults to the work tree as it is. The builds share this
# checkout's target directory, so only the cumulus crate is rebuilt.
set -euo pipefail
cd "$(dirname "$0")/.."
old=${1:?usage: .ci/render_identity.sh OLD_COMMIT [NEW_COMMIT]}
new=${2:-}
backends=${BACKENDS:-cpu}
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$PWD/target}"
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-$(mktemp -d)}"
work=$(mktemp -d)
cleanup() {
  for t in old new; do
    [ -d "$work/$t" ] && git worktree remove --force "$work/$t" >/dev/null 2>&1 || true
  done
  rm -rf "$work"
}
trap cleanup EXIT

# build NAME TREE: builds the binary of TREE and keeps it as $work/NAME.bin.
build() {
  (cd "$2" && cargo build --release --quiet --bin cumulus)
  cp "$CARGO_TARGET_DIR/release/cumulus" "$work/$1.bin"
}

git worktree add --quiet --detach "$work/old" "$old"
build old "$work/old"
if [ -n "$new" ]; then
  git worktree add --quiet --detach "$work/new" "$new"
  build new "$work/new"
  new_tree="$work/new"
else
  build new "$PWD"
  new_tree="$PWD"
fi

status=0
for scene in "$work"/old/scenes/*.toml; do
  name=$(basename "$scene" .toml)
  for backend in $backends; do
    args=(render --scene "scenes/$name.toml" --backend "$backend")
    size=${SIZE:-}
    [ "$backend" = gpu ] && size=${size:-320x240} && args+=(--frames 8)
    [ -n "$size" ] && args+=(--width "${size%x*}" --height "${size#*x}")
    [ -n "${PHOTONS:-}" ] && args+=(--light-photons "$PHOTONS")
    for side in old new; do
      tree="$work/old"; [ "$side" = new ] && tree="$new_tree"
      (cd "$tree" && "$work/$side.bin" "${args[@]}" --out "$work/$side-$backend-$name.png" 2>/dev/null)
    done
    if cmp -s "$work/old-$backend-$name.png" "$work/new-$backend-$name.png"; then
      echo "same bytes: $name ($backend)"
    else
      echo "DIFFERENT: $name ($backend)"
      status=1
    fi
  done
done
exit $status
