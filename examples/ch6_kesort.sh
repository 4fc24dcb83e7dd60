#!/usr/bin/env bash
# Chapter 6 end to end through the CLI alone: optimise Parts A, B and C (Table 6.1,
# examples/ch6_optimise.sh), then choose each Part's optimum by k-ε optimality as Sec 6.2.2
# does (Tables 6.2-6.3, Fig. 6.7):
#   Part A  the four single-objective optima C1-C4 pooled, f1-f6 re-simulated, P = 0.60
#   Part B  the f1-f3 front with f4-f6 re-simulated (supplementary), P = 0.55
#   Part C  the f1-f6 front, P = 0.65
# (the P of Eq 6.19 as the thesis prints them), and finally all three Parts pooled with the
# automatic P. Files go to OUT (default ./out/ch6). SUSPOPT_QUICK=1 runs on a tiny budget
# (CI) and then also sorts infeasible designs, which a tiny budget may leave alone.
#   examples/ch6_kesort.sh [OUT]
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:-out/ch6}"
keep=()
[[ "${SUSPOPT_QUICK:-0}" == "1" ]] && keep=(--keep-infeasible)
"$here/examples/ch6_optimise.sh" "$out"
part_a=("$out"/part_a_c{1,2,3,4}.h5)
label_a=(-l "Part A" -l "Part A" -l "Part A" -l "Part A")
echo "== Part A"
suspopt kesort "${part_a[@]}" "${label_a[@]}" --P 0.60 "${keep[@]}" -o "$out/kesort_part_a.h5"
echo "== Part B"
suspopt kesort "$out/part_b.h5" -l "Part B" --P 0.55 "${keep[@]}" -o "$out/kesort_part_b.h5" \
    --plot "$out/kesort_part_b.png"
echo "== Part C"
suspopt kesort "$out/part_c.h5" -l "Part C" --P 0.65 "${keep[@]}" -o "$out/kesort_part_c.h5" \
    --plot "$out/kesort_part_c.png"
echo "== Parts A, B and C pooled"
suspopt kesort "${part_a[@]}" "$out/part_b.h5" "$out/part_c.h5" "${label_a[@]}" \
    -l "Part B" -l "Part C" "${keep[@]}" -o "$out/kesort.h5" --plot "$out/kesort.png"
