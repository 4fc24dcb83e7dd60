#!/usr/bin/env bash
# Chapter 6: Parts A, B and C of Table 6.1 (seat and passenger on the HC2),
# through the CLI alone: one HDF5 file per config in OUT (default ./out/ch6). The thesis's
# budgets take hours; SUSPOPT_QUICK=1 runs every config on a tiny budget (see
# examples/optimise_configs.sh), e.g. in CI:  SUSPOPT_QUICK=1 examples/ch6_optimise.sh
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
"$here/examples/optimise_configs.sh" "${1:-out/ch6}" "$here"/configs/ch6/*.yaml
