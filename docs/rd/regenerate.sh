#!/usr/bin/env bash
# Regenerates docs/rd/: the rate-distortion curves of whet's swing mode (decoded, sharpened,
# sharpened + Bender) and of the exact mode (Draco's kind of codec) on the public fixtures,
# with Draco's anchors on the same plots and the bytes each curve needs for Draco's
# quantization-10 RMS error (vs-draco.md). Needs ../shared beside the checkout.
# Run from the repository root: bash docs/rd/regenerate.sh   (about 20 minutes on 2 cores)
set -euo pipefail
cd "$(dirname "$0")/../.."
shared=../shared
meshes=()
for m in fandisk block joint partLp cad_box_hole cad_bracket cad_cyl_fillet rocker_arm \
         sharp_sphere screwdriver bunny spot fertility armadillo; do
  meshes+=("$shared/fixtures/$m.off")
done
cargo run --release --quiet -- rd "${meshes[@]}" \
  --modes swing,exact \
  --rates 0.5,1,2,3,4,6,8,12,16 \
  --exact-bits 6,7,8,9,10,11,12,14 \
  --stages decoded,sharpened,bent \
  --exact-stages decoded \
  --samples 300000 --seed 0 \
  --draco "$shared/anchors/draco.md" \
  --out docs/rd > /dev/null
echo "wrote docs/rd/rd.md, rd.csv, rd.json, vs-draco.md and one SVG per mesh"
