#!/usr/bin/env bash
# Chapter 8: RC_se against X_ST fronts of the five seat isolators on class A and B,
# through the CLI alone: one HDF5 file per config in OUT (default ./out/ch8); CLASS (a, b or
# both, the default) picks the roads:  examples/ch8_optimise.sh [OUT] [CLASS...]. The thesis's
# budgets take hours; SUSPOPT_QUICK=1 runs every config on a tiny budget (see
# examples/optimise_configs.sh), e.g. in CI:  SUSPOPT_QUICK=1 examples/ch8_optimise.sh
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:-out/ch8}"
shift $(( $# > 0 ? 1 : 0 ))
configs=()
for road in ${*:-a b}; do
    configs+=("$here"/configs/ch8/pareto_*_class_"$road".yaml)
done
"$here/examples/optimise_configs.sh" "$out" "${configs[@]}"
