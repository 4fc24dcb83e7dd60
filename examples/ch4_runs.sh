#!/usr/bin/env bash
# Chapter 4 (Tables 4.2-4.3, Figs. 4.7 and 4.10) through the CLI alone: every config of
# configs/ch4 simulated (OUT/<config>.h5, default OUT ./out/ch4); the CDF configs again with
# the two fits they do not use (OUT/fits/, written by examples/ch4_tables.py --fits from the
# stored runs); the C_max share sweep of the CDF strategy on class C for both laws
# (OUT/<law>_cdf_sensitivity.{h5,png}). Then `python examples/ch4_tables.py OUT` prints the
# tables. SUSPOPT_QUICK=1 shortens every run to 3 s (examples/budget_config.sh), e.g. in CI.
#   examples/ch4_runs.sh [OUT]
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:-out/ch4}"
mkdir -p "$out"
for path in "$here"/configs/ch4/*.yaml; do
    name="$(basename "$path" .yaml)"
    echo "== $name"
    suspopt simulate "$("$here/examples/budget_config.sh" "$path" "$out/configs")" \
        -o "$out/$name.h5" > /dev/null
done
echo "== the other threshold fits"
# a separate assignment, so that a failing check stops the script (set -e)
fits="$(python "$here/examples/ch4_tables.py" --fits "$out")"
for path in $fits; do
    echo "   $(basename "$path" .yaml)"
    suspopt simulate "$path" -o "${path%.yaml}.h5" > /dev/null
done
for law in sh_2 sh_add_2; do
    echo "== $law: C_max share sweep, class C"
    suspopt analyse cdf-sensitivity \
        "$("$here/examples/budget_config.sh" "$here/configs/ch4/${law}_cdf_class_c.yaml" "$out/configs")" \
        -o "$out/${law}_cdf_sensitivity.h5" --plot "$out/${law}_cdf_sensitivity.png"
done
