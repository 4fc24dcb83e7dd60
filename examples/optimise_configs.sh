#!/usr/bin/env bash
# Optimise every config matching the given files through the CLI alone, as a CI job would:
#   examples/optimise_configs.sh OUT CONFIG...
# one HDF5 file per config in OUT. With SUSPOPT_QUICK=1 (a tiny budget, so a whole chapter
# runs in minutes) or SUSPOPT_MAX_EVALUATIONS, SUSPOPT_POPULATION, SUSPOPT_GENERATIONS each
# config is first copied to OUT/configs with that budget (examples/budget_config.sh); the
# copies keep everything else.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
out="$1"; shift
mkdir -p "$out"
for cfg in "$@"; do
    name="$(basename "$cfg" .yaml)"
    cfg="$("$here/budget_config.sh" "$cfg" "$out/configs")"
    echo "== $name"
    suspopt validate "$cfg"
    suspopt optimise "$cfg" -o "$out/$name.h5"
done
