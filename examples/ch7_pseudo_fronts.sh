#!/usr/bin/env bash
# Chapter 7 pseudo-fronts (Sec 7.3, Fig. 7.4b): the SH-2 and SH-ADD-2 fronts that
# examples/ch7_optimise.sh wrote to OUT (default ./out/ch7) re-simulated with the CDF strategy
# (configs/ch7/controllers/cdf.yaml), one batch each: OUT/<law>_cdf.h5 and OUT/<law>_cdf.png.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:-out/ch7}"
for law in sh_2 sh_add_2; do
    echo "== $law -> $law-CDF"
    suspopt analyse controllers "$out/$law.h5" --with "$here/configs/ch7/controllers/cdf.yaml" \
        -o "$out/${law}_cdf.h5" --plot "$out/${law}_cdf.png"
done
