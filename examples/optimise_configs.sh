#!/usr/bin/env bash
# Optimise every config matching the given files through the CLI alone, as a CI job would:
#   examples/optimise_configs.sh OUT CONFIG...
# one HDF5 file per config in OUT. With SUSPOPT_QUICK=1 each config is first copied to
# OUT/configs with a tiny budget (population 8, 2 generations, 8 balancing samples, at most
# 3 s of simulated time), so a whole chapter runs in minutes; the copies keep everything else.
set -euo pipefail
out="$1"; shift
mkdir -p "$out/configs"
for cfg in "$@"; do
    name="$(basename "$cfg" .yaml)"
    if [[ "${SUSPOPT_QUICK:-0}" == "1" ]]; then
        quick="$out/configs/$name.yaml"
        sed -E -e 's/^(  population:) [0-9]+/\1 8/' \
               -e 's/^(  generations:) [0-9]+/\1 2/' \
               -e 's/(samples:) [0-9]+/\1 8/' \
               -e 's/^simulation: \{duration: [0-9.]+/simulation: {duration: 3.0/' \
               "$cfg" > "$quick"
        cfg="$quick"
    fi
    echo "== $name"
    suspopt validate "$cfg"
    suspopt optimise "$cfg" -o "$out/$name.h5"
done
