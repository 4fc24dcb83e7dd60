#!/usr/bin/env bash
# Chapter 7 pseudo-fronts (Sec 7.3, Fig. 7.4b): the SH-2 and SH-ADD-2 fronts that
# examples/ch7_optimise.sh wrote to OUT (default ./out/ch7) re-simulated with the CDF strategy
# (the control: section of configs/ch7/<law>_cdf.yaml), one batch each: OUT/<law>_cdf.h5 and
# OUT/<law>_cdf.png (examples/ch7_kesort.sh sorts the same pseudo-fronts by k-ε optimality).
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:-out/ch7}"
for law in sh_2 sh_add_2; do
    echo "== $law -> $law-CDF"
    suspopt analyse controllers "$out/$law.h5" --with "$here/configs/ch7/${law}_cdf.yaml" \
        -o "$out/${law}_cdf.h5" --plot "$out/${law}_cdf.png"
done
