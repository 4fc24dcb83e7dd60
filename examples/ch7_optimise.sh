#!/usr/bin/env bash
# Chapter 7: NSGA-II fronts of the SH-2, ADD and SH-ADD-2 semi-active cars (Table 7.2),
# through the CLI alone: one HDF5 file per config in OUT (default ./out/ch7). The thesis's
# budgets take hours; SUSPOPT_QUICK=1 runs every config on a tiny budget (see
# examples/optimise_configs.sh), e.g. in CI:  SUSPOPT_QUICK=1 examples/ch7_optimise.sh
# (configs/ch7/*_cdf.yaml are not optimised: examples/ch7_kesort.sh simulates the fronts
# with them.)
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
"$here/examples/optimise_configs.sh" "${1:-out/ch7}" "$here"/configs/ch7/{sh_2,add,sh_add_2}.yaml
