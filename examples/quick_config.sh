#!/usr/bin/env bash
# Print the config a batch job should run:
#   examples/quick_config.sh CONFIG DIR
# CONFIG itself; with SUSPOPT_QUICK=1 a copy written to DIR with a tiny budget (population 8,
# 2 generations, 8 balancing samples, at most 3 s of simulated time) that keeps everything else.
set -euo pipefail
cfg="$1"; dir="$2"
if [[ "${SUSPOPT_QUICK:-0}" == "1" ]]; then
    mkdir -p "$dir"
    quick="$dir/$(basename "$cfg")"
    sed -E -e 's/^(  population:) [0-9]+/\1 8/' \
           -e 's/^(  generations:) [0-9]+/\1 2/' \
           -e 's/(samples:) [0-9]+/\1 8/' \
           -e 's/^simulation: \{duration: [0-9.]+/simulation: {duration: 3.0/' \
           "$cfg" > "$quick"
    echo "$quick"
else
    echo "$cfg"
fi
