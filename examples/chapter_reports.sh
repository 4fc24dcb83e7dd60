#!/usr/bin/env bash
# One interactive report per chapter with design sets (suspopt report), from the outputs of
# examples/reproduce_thesis.sh:  examples/chapter_reports.sh [OUT] [HTMLDIR]
# (defaults out/report and OUT/html). Chapters 3 and 4 simulate given designs and have no
# design sets to explore; Ch. 5: the optimum of each case under S1 (Table 5.3); Ch. 6: the
# k-ε sort of all parts and the Part B front; Ch. 7: the k-ε sort of the controllers and the
# SH-2 and SH-ADD-2 fronts under the CDF threshold (Fig. 7.4b); Ch. 8: the PS and NSS4 fronts
# on class A and their pseudo-fronts on other roads and passengers (Tables 8.12-8.13).
# Then examples/report_screenshots.py draws each page in headless Chromium (when installed),
# checks it, and writes HTMLDIR/<chapter>.png.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:-out/report}"
html="${2:-$out/html}"
mkdir -p "$html"
suspopt report "$out"/ch5/case{1,2,3,4,5}_s1.h5 --title "Chapter 5: the optimum of each case (S1)" \
    -o "$html/ch5.html" --force
suspopt report "$out/ch6/kesort.h5" "$out/ch6/part_b.h5" --title "Chapter 6: k-ε sort and Part B" \
    -o "$html/ch6.html" --force
suspopt report "$out/ch7/kesort.h5" "$out"/ch7/{sh_2,sh_add_2}_cdf.h5 \
    --title "Chapter 7: controllers, k-ε sort and CDF pseudo-fronts" -o "$html/ch7.html" --force
suspopt report "$out"/ch8/pareto_{ps,nss4}_class_a.h5 "$out"/ch8/ps_{roads,masses}.h5 \
    --title "Chapter 8: seat fronts and pseudo-fronts" -o "$html/ch8.html" --force
if command -v chromium >/dev/null && python -c "import selenium" 2>/dev/null; then
    python "$here/examples/report_screenshots.py" "$html"/ch{5,6,7,8}.html
fi
