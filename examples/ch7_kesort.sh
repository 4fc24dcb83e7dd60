#!/usr/bin/env bash
# Chapter 7 end to end through the CLI alone: optimise the SH-2, ADD and SH-ADD-2 fronts
# (Table 7.2, examples/ch7_optimise.sh), simulate the SH-2 and SH-ADD-2 fronts again with the
# CDF strategy (configs/ch7/*_cdf.yaml: the "pseudo Pareto fronts" of Fig. 7.4b), then sort
# the five cases of Table 7.4 by k-ε optimality on f1-f6 (Eq 7.1-7.2, 7.7-7.10), each case
# alone (Fig. 7.5) and all pooled (Fig. 7.6), with P searched in the thesis's 0.10-0.20
# (Sec 7.2.2): Tables 7.5-7.6. Files go to OUT (default ./out/ch7). SUSPOPT_QUICK=1 runs on
# a tiny budget (CI) and then also sorts infeasible designs.
#   examples/ch7_kesort.sh [OUT]
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:-out/ch7}"
keep=()
[[ "${SUSPOPT_QUICK:-0}" == "1" ]] && keep=(--keep-infeasible)
"$here/examples/ch7_optimise.sh" "$out"
configs=()
for name in sh_2 add sh_add_2 sh_2_cdf sh_add_2_cdf; do
    configs+=(-c "$("$here/examples/budget_config.sh" "$here/configs/ch7/$name.yaml" "$out/configs")")
done
echo "== Table 7.4: SH-2, ADD, SH-ADD-2, SH-2-CDF, SH-ADD-2-CDF"
suspopt kesort "$out"/{sh_2,add,sh_add_2,sh_2,sh_add_2}.h5 "${configs[@]}" \
    -l SH-2 -l ADD -l SH-ADD-2 -l SH-2-CDF -l SH-ADD-2-CDF --P-range 0.10,0.20 "${keep[@]}" \
    -o "$out/kesort.h5" --plot "$out/kesort.png"
