#!/usr/bin/env bash
# Print the config a batch job should run:
#   examples/budget_config.sh CONFIG DIR
# CONFIG itself, or a copy written to DIR that keeps everything but the budget:
#   SUSPOPT_QUICK=1             a tiny budget for CI: population 8, 2 generations, 8 balancing
#                               samples, at most 3 s of simulated time, CDF thresholds learnt
#                               for 1 s (so a fit happens within the 3 s)
#   SUSPOPT_MAX_EVALUATIONS=N   at most N designs simulated per run (optimiser.max_evaluations;
#                               the run stops at whichever of the budgets comes first)
#   SUSPOPT_POPULATION=N        optimiser.population
#   SUSPOPT_GENERATIONS=N       optimiser.generations
# SUSPOPT_QUICK=1 overrides the other three. A config without an optimiser keeps its budget
# (only SUSPOPT_QUICK shortens its run).
set -euo pipefail
cfg="$1"; dir="$2"
edits=()
if [[ "${SUSPOPT_QUICK:-0}" == "1" ]]; then
    edits=(-e 's/^(  population:) [0-9]+/\1 8/'
           -e 's/^(  generations:) [0-9]+/\1 2/'
           -e 's/(samples:) [0-9]+/\1 8/'
           -e 's/^simulation: \{duration: [0-9.]+/simulation: {duration: 3.0/'
           -e 's/^( *learn_time:) [0-9.]+/\1 1.0/')
else
    [[ -n "${SUSPOPT_POPULATION:-}" ]] && edits+=(-e "s/^(  population:) [0-9]+/\1 $SUSPOPT_POPULATION/")
    [[ -n "${SUSPOPT_GENERATIONS:-}" ]] && edits+=(-e "s/^(  generations:) [0-9]+/\1 $SUSPOPT_GENERATIONS/")
    [[ -n "${SUSPOPT_MAX_EVALUATIONS:-}" ]] && edits+=(
        -e '/^  max_evaluations:/d'
        -e "s/^(optimiser:.*)$/\1\n  max_evaluations: $SUSPOPT_MAX_EVALUATIONS/")
fi
if (( ${#edits[@]} )); then
    mkdir -p "$dir"
    copy="$dir/$(basename "$cfg")"
    sed -E "${edits[@]}" "$cfg" > "$copy"
    echo "$copy"
else
    echo "$cfg"
fi
