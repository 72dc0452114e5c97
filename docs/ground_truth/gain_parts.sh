#!/usr/bin/env bash
# One-off builds of the CPU renderer for fitting the light's six gains
# (fit_gains.py): `zero` with all six at 0, and one build per gain with
# that gain at 1 and the others at 0. Our image is linear in the gains,
# so any set of gains is the zero build's image plus the parts'.
#
#   docs/ground_truth/gain_parts.sh OUTDIR
#
# Writes OUTDIR/cumulus_{zero,mf,mi,di,fl,am,gr}. Edits the source file
# that holds the gains (lighting.rs) in place and restores it on exit (also on error
# or Ctrl-C), then rebuilds the shipped binary. About a minute a build.
# Honours CARGO_TARGET_DIR (builds there, so a binary another script is
# running from target/ is left alone).
set -euo pipefail
cd "$(dirname "$0")/../.."
out=${1:?usage: gain_parts.sh OUTDIR}
mkdir -p "$out"
L=src/render/cpu/lighting.rs
keep=$(mktemp -d)
cp "$L" "$keep/"
restore() {
  cp "$keep/lighting.rs" "$L"
  rm -rf "$keep"
}
trap restore EXIT
for v in zero mf mi di fl am gr; do
  mf=0.0 mi=0.0 di=0.0 fl=0.0 am=0.0 gr=0.0
  case $v in mf) mf=1.0 ;; mi) mi=1.0 ;; di) di=1.0 ;; fl) fl=1.0 ;; am) am=1.0 ;; gr) gr=1.0 ;; esac
  cp "$keep/lighting.rs" "$L"
  sed -i "s/^pub const MULTIPLE_GAIN: f32 = .*/pub const MULTIPLE_GAIN: f32 = $mf;/;
          s/^pub const MULTIPLE_ISOTROPIC_GAIN: f32 = .*/pub const MULTIPLE_ISOTROPIC_GAIN: f32 = $mi;/;
          s/^pub const DIFFUSE_GAIN: f32 = .*/pub const DIFFUSE_GAIN: f32 = $di;/;
          s/^pub const FLUENCE_GAIN: f32 = .*/pub const FLUENCE_GAIN: f32 = $fl;/" "$L"
  sed -i "s/^pub const AMBIENT_GAIN: f32 = .*/pub const AMBIENT_GAIN: f32 = $am;/;
          s/^pub const GROUND_LIGHT_GAIN: f32 = .*/pub const GROUND_LIGHT_GAIN: f32 = $gr;/" "$L"
  cargo build --release --bin cumulus
  cp "${CARGO_TARGET_DIR:-target}/release/cumulus" "$out/cumulus_$v"
done
restore
trap - EXIT
cargo build --release --bin cumulus
echo "wrote $out/cumulus_{zero,mf,mi,di,fl,am,gr}"
