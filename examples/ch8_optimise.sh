#!/usr/bin/env bash
# Chapter 8: RC_se against X_ST fronts of the five seat isolators on class A and B,
# through the CLI alone: one HDF5 file per config in OUT (default ./out/ch8). The thesis's
# budgets take hours; SUSPOPT_QUICK=1 runs every config on a tiny budget (see
# examples/optimise_configs.sh), e.g. in CI:  SUSPOPT_QUICK=1 examples/ch8_optimise.sh
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
"$here/examples/optimise_configs.sh" "${1:-out/ch8}" "$here"/configs/ch8/pareto_*.yaml
