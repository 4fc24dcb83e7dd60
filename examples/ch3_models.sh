#!/usr/bin/env bash
# Chapter 3 comparison of vehicle models, run as a CI job would: every config through the CLI,
# one HDF5 file each in OUT (default ./out/ch3), then the comparisons of Tables 3.3-3.21
# (suspopt analyse models: OUT/<part>.h5 and OUT/<part>.png).
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:-out/ch3}"
cfg="$here/configs/ch3"
mkdir -p "$out"
for path in "$cfg"/*.yaml; do
    name="$(basename "$path" .yaml)"
    echo "== $name"
    suspopt simulate "$path" -o "$out/$name.h5"
done
for road in bump class_b; do
    for part in part1a part1b; do          # Part 1: QC is the reference, as the tables
        echo "== $part models, $road"
        suspopt analyse models "$cfg/${part}_"{qc,hc1,hc2,fc}"_$road.yaml" \
            -o "$out/${part}_models_$road.h5" --plot "$out/${part}_models_$road.png"
    done
    echo "== part2a anti-roll bars, $road"   # Part 2: the car without the element is the reference
    suspopt analyse models "$cfg/part2a_fc_"{no_arb,arb}"_$road.yaml" \
        -o "$out/part2a_models_$road.h5" --plot "$out/part2a_models_$road.png"
    echo "== part2b tyre damping, $road"
    suspopt analyse models "$cfg/part2b_qc_"{ct0,ct49}"_$road.yaml" \
        -o "$out/part2b_models_$road.h5" --plot "$out/part2b_models_$road.png"
done
