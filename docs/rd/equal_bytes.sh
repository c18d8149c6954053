#!/usr/bin/env bash
# The swing mode's RMS error at an exact byte count, which a rate search only lands within
# 5 % of: encodes MESH at each edge length (fractions of the bounding-box diagonal), decodes,
# measures the symmetric RMS with `whet metro` (1 000 000 samples), and fits log RMS against
# log bytes by least squares, then evaluates the fit at BYTES (docs/results.md,
# "Neighbourhood prediction"). Run from the repository root, e.g.
#   bash docs/rd/equal_bytes.sh ../shared/fixtures/bunny.off 5653 0.0072 0.0073 ... 0.0084
# WHET=path/to/whet measures another build (default: target/release/whet, built here).
set -euo pipefail
mesh=$1; target=$2; shift 2
whet=${WHET:-target/release/whet}
[ -n "${WHET:-}" ] || cargo build --release --quiet --bin whet
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
for l in "$@"; do
  # With fixed angle bits "angle_trials" is empty: the first "bytes" is the stream's.
  bytes=$("$whet" encode "$mesh" -o "$tmp/s.whet" --edge-length "$l" --angle-bits 6 --json |
    grep -o '"bytes":[0-9]*' | head -1 | cut -d: -f2)
  "$whet" decode "$tmp/s.whet" -o "$tmp/d.ply" 2>/dev/null
  # The last "rms_pct" of the (key-sorted) JSON is the symmetric one.
  rms=$("$whet" metro "$mesh" "$tmp/d.ply" --samples 1000000 --json |
    grep -o '"rms_pct":[0-9.e-]*' | tail -1 | cut -d: -f2)
  echo "$l $bytes $rms"
done | tee "$tmp/points"
awk -v t="$target" '{ x = log($2); y = log($3); n++; sx += x; sy += y; sxx += x*x; sxy += x*y }
  END { b = (n*sxy - sx*sy) / (n*sxx - sx*sx); a = (sy - b*sx) / n;
        printf "fit: slope %.3f, RMS at %d bytes %.5f %%\n", b, t, exp(a + b*log(t)) }' "$tmp/points"
