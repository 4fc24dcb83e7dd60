#!/usr/bin/env bash
# Chapter 3 comparison of vehicle models, run as a CI job would: every config through the CLI,
# one HDF5 file each in OUT (default ./out/ch3), then the comparisons of Tables 3.3-3.21
# (suspopt analyse models: OUT/<part>_models_<road>.h5 and .png). SUSPOPT_QUICK=1 shortens
# every run to 3 s (examples/budget_config.sh), e.g. in CI.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:-out/ch3}"
cfg="$here/configs/ch3"
mkdir -p "$out"
run() { "$here/examples/budget_config.sh" "$cfg/$1.yaml" "$out/configs"; }
for path in "$cfg"/*.yaml; do
    name="$(basename "$path" .yaml)"
    echo "== $name"
    suspopt simulate "$(run "$name")" -o "$out/$name.h5"
done
models() {      # models PART ROAD MODEL...: the first model is the reference
    local part="$1" road="$2"; shift 2
    local configs=()
    for model in "$@"; do configs+=("$(run "${part}_${model}_$road")"); done
    suspopt analyse models "${configs[@]}" \
        -o "$out/${part}_models_$road.h5" --plot "$out/${part}_models_$road.png"
}
for road in bump class_b; do
    for part in part1a part1b; do          # Part 1: QC is the reference, as the tables
        echo "== $part models, $road"
        models "$part" "$road" qc hc1 hc2 fc
    done
    echo "== part2a anti-roll bars, $road"   # Part 2: the car without the element is the reference
    models part2a "$road" fc_no_arb fc_arb
    echo "== part2b tyre damping, $road"
    models part2b "$road" qc_ct0 qc_ct49
done
