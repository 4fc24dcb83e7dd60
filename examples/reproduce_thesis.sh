#!/usr/bin/env bash
# The reproduction report of the thesis in one command, from a clean checkout (after
# `python -m pip install -e .`):
#
#   examples/reproduce_thesis.sh [OUT] [REPORT]
#
# runs every chapter's configs through the CLI alone (examples/ch3_models.sh ... ch8_stht.sh:
# suspopt simulate, optimise, kesort, analyse), writing HDF5 files and figures under OUT
# (default out/report/chN/, one log per step in OUT/logs/, the steps' wall times in
# OUT/run.tsv), then examples/report.py writes REPORT (default report/): README.md (header,
# budgets, headlines) and ch3.md ... ch8.md, each thesis table beside ours with the
# difference and its reason, and the figures in REPORT/figures/. OUT/html/ch5.html ...
# ch8.html are the chapters' interactive reports (examples/chapter_reports.sh).
#
# Budgets (the report states them next to each table):
#   Ch. 3, 4   the configs as they are (full runs);
#   Ch. 5      every run at most CH5_MAX_EVALUATIONS designs (default 120000 = S1's full
#              MATLAB budget, 200 x 600): S1 and S3-S5 are not cut, S2 (population 1000)
#              stops after 120 of its 600 generations unless it stalls first;
#   Ch. 6-8    the configs' population 100 and 100 generations (Ch. 6-8 state no budget).
# SUSPOPT_QUICK=1 runs everything on a tiny budget (population 8, 2 generations, 3 s runs;
# examples/budget_config.sh) and writes the whole report structure in a few minutes, for CI.
# Its wall times on the 2-core development machine are on docs/performance.md; run it under
# `nice -n 10` on a shared machine.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:-out/report}"
report="${2:-report}"
ch5_evaluations="${CH5_MAX_EVALUATIONS:-120000}"
mkdir -p "$out/logs"
: > "$out/run.tsv"
if [[ "${SUSPOPT_QUICK:-0}" == "1" ]]; then
    echo "budget: SUSPOPT_QUICK=1 (population 8, 2 generations, 8 balancing samples, 3 s runs)"
    ch5_budget="quick"
    echo quick > "$out/mode"
    unset SUSPOPT_MAX_EVALUATIONS SUSPOPT_POPULATION SUSPOPT_GENERATIONS
else
    echo "budget: Ch. 3-4 full runs; Ch. 5 at most $ch5_evaluations evaluations per run;" \
         "Ch. 6-8 population 100, 100 generations"
    ch5_budget="$ch5_evaluations"
    echo "full $ch5_evaluations" > "$out/mode"
fi
start=$SECONDS

step() {        # step NAME COMMAND...: run one step, log it to OUT/logs/NAME.log, time it
    local name="$1"; shift
    local t0=$SECONDS
    printf '== %-12s %s\n' "$name" "$*"
    if ! "$@" > "$out/logs/$name.log" 2>&1; then
        tail -n 30 "$out/logs/$name.log"
        echo "step $name failed (log: $out/logs/$name.log)" >&2
        exit 1
    fi
    printf '%s\t%s\t%s\n' "$name" "$((SECONDS - t0))" "$*" >> "$out/run.tsv"
    printf '   %-12s %d s\n' "$name" "$((SECONDS - t0))"
}

variant() {     # variant CONFIG NAME SED-EXPR...: CONFIG (after the budget) edited, in checks/
    local dir="$out/ch3/checks" src dst
    src="$("$here/examples/budget_config.sh" "$1" "$dir/budget")"
    dst="$dir/$2.yaml"; shift 2
    mkdir -p "$dir"
    sed -E "$@" "$src" > "$dst"
    suspopt simulate "$dst" -o "${dst%.yaml}.h5"
}

ch3_checks() {  # the measurements behind Ch. 3's "why they differ": step size, seed, length
    variant "$here/configs/ch3/part1a_qc_bump.yaml" part1a_qc_bump_dt_half \
        -e 's/dt: 1\.0e-3/dt: 5.0e-4/'
    for seed in 2 3 4 5; do      # seed 1 is the configs' own, run by ch3_models.sh
        for model in qc fc; do
            variant "$here/configs/ch3/part1a_${model}_class_b.yaml" \
                "part1a_${model}_class_b_seed_$seed" -e "s/^(  seed:) 1$/\1 $seed/"
        done
    done
    variant "$here/configs/ch3/part1a_qc_class_b.yaml" part1a_qc_class_b_double_length \
        -e 's/duration: 60\.0/duration: 120.0/'
}

step ch3 "$here/examples/ch3_models.sh" "$out/ch3"
step ch3_checks ch3_checks
step ch4 "$here/examples/ch4_runs.sh" "$out/ch4"
if [[ "$ch5_budget" == "quick" ]]; then
    step ch5 "$here/examples/ch5_optimise.sh" "$out/ch5"
else
    step ch5 env SUSPOPT_MAX_EVALUATIONS="$ch5_evaluations" \
        "$here/examples/ch5_optimise.sh" "$out/ch5"
fi
step ch6 "$here/examples/ch6_kesort.sh" "$out/ch6"
step ch7 "$here/examples/ch7_kesort.sh" "$out/ch7"
step ch7_pseudo "$here/examples/ch7_pseudo_fronts.sh" "$out/ch7"
step ch8 "$here/examples/ch8_optimise.sh" "$out/ch8" a b
step ch8_pseudo "$here/examples/ch8_pseudo_fronts.sh" "$out/ch8"
step ch8_stht "$here/examples/ch8_stht.sh" "$out/ch8"
step reports "$here/examples/chapter_reports.sh" "$out" "$out/html"
step report python "$here/examples/report.py" "$out" "$report" --wall "$((SECONDS - start))"
echo "report: $report/README.md ($((SECONDS - start)) s)"
