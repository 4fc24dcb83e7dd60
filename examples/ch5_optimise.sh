#!/usr/bin/env bash
# Chapter 5: Cases 1-5 x scenarios S1-S5 of Table 5.3 (GA, hybrid, SLSQP, weighted sums),
# through the CLI alone: one HDF5 file per config in OUT (default ./out/ch5). The thesis's
# budgets take hours; SUSPOPT_QUICK=1 runs every config on a tiny budget (see
# examples/optimise_configs.sh), e.g. in CI:  SUSPOPT_QUICK=1 examples/ch5_optimise.sh
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
"$here/examples/optimise_configs.sh" "${1:-out/ch5}" "$here"/configs/ch5/*.yaml
