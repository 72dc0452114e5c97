#!/usr/bin/env bash
# The 2026-12-06 experiment: the light volume's diffused sunlight (and,
# with CUMULUS_SKY_MC, the sky's light in cloud) replaced by Monte Carlo
# transport on the light grid (src/render/cpu/light_transport.rs), the
# six gains refitted against the stored path-traced references.
#
#   docs/ground_truth/gain_parts.sh /tmp/parts          # the shipped parts
#   docs/ground_truth/transport_fit.sh /tmp/parts /tmp/transport_parts
#   CUMULUS_LIGHT_MC=16000000 python3 docs/ground_truth/fit_gains.py \
#       --bins /tmp/transport_parts --arrays /tmp/arrays --views backlit,high_sun \
#       --cache /tmp/fit_transport
#
# (--arrays: compare.py --arrays --out /tmp/arrays on the same views.)
# Environment read by the patched build: CUMULUS_LIGHT_MC (photons for
# the sun's light; unset: the diffusion), CUMULUS_SKY_MC (photons for the
# sky's light from above and from below; unset: the shipped profiles),
# CUMULUS_SUN_SH (photons for the sun's light held as spherical harmonics
# to l = 2 instead of fluence and flux; CUMULUS_SH_ORDER=1 keeps only
# l <= 1),
# CUMULUS_LIGHT_CELL (the grid's cell, m; 80 unset). The sky's and the
# SH volumes are built lazily by the first pixel that needs them, inside
# the render's own parallel loop, so on one core while the other waits:
# 16 M photons at 80 m take about a minute; 64 M at 40 m did not finish a
# view in 15 minutes and was stopped. fit_gains.py's cache
# is keyed by the binary, not by these: give each setting its own --cache.
#
# The transport has shipped since (2026-12-06, third session: the light
# volume is the l = 2 transport); the experiment stays reproducible on
# the tree it was measured on, BEFORE (the commit below), where the
# patch applies and the SHIPPED_PARTS were built.
#
# Builds the patch (transport_experiment.patch) in a worktree of BEFORE at
# /tmp/transport_wt, with its own target directory, and writes
# OUTDIR/cumulus_{fl,am,gr} from it (the light volume's, the sky's and
# the ground's parts; the other four parts are linked from SHIPPED_PARTS,
# whose images the patch does not change). Nothing in this checkout is
# edited.
set -euo pipefail
cd "$(dirname "$0")/../.."
shipped=${1:?usage: transport_fit.sh SHIPPED_PARTS OUTDIR}
out=${2:?usage: transport_fit.sh SHIPPED_PARTS OUTDIR}
wt=/tmp/transport_wt
patch=$(pwd)/docs/ground_truth/transport_experiment.patch
rm -rf "$wt"
git worktree prune
BEFORE=03dfb3f
git worktree add -q --detach "$wt" "$BEFORE"
trap 'git worktree remove --force "$wt"' EXIT
(cd "$wt" && git apply "$patch")
mkdir -p "$out"
L=src/render/cpu/lighting.rs
R=src/render/cpu/renderer.rs
for v in fl am gr; do
  fl=0.0 am=0.0 gr=0.0
  case $v in fl) fl=1.0 ;; am) am=1.0 ;; gr) gr=1.0 ;; esac
  (cd "$wt" && git checkout -q -- "$L" "$R" && git apply --include="$R" "$patch" &&
    sed -i "s/^pub const MULTIPLE_GAIN: f32 = .*/pub const MULTIPLE_GAIN: f32 = 0.0;/;
            s/^pub const MULTIPLE_ISOTROPIC_GAIN: f32 = .*/pub const MULTIPLE_ISOTROPIC_GAIN: f32 = 0.0;/;
            s/^pub const DIFFUSE_GAIN: f32 = .*/pub const DIFFUSE_GAIN: f32 = 0.0;/;
            s/^pub const FLUENCE_GAIN: f32 = .*/pub const FLUENCE_GAIN: f32 = $fl;/" "$L" &&
    sed -i "s/^pub const AMBIENT_GAIN: f32 = .*/pub const AMBIENT_GAIN: f32 = $am;/;
            s/^pub const GROUND_LIGHT_GAIN: f32 = .*/pub const GROUND_LIGHT_GAIN: f32 = $gr;/" "$R" &&
    CARGO_TARGET_DIR=/tmp/transport_target cargo build --release --bin cumulus)
  cp /tmp/transport_target/release/cumulus "$out/cumulus_$v"
done
for v in zero mf mi di; do
  ln -sf "$(readlink -f "$shipped/cumulus_$v")" "$out/cumulus_$v"
done
echo "wrote $out/cumulus_{fl,am,gr} (and linked the shipped zero, mf, mi, di)"
