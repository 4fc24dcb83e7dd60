#!/usr/bin/env bash
# Chapter 8, Analyses 1-3 (Sec 8.4.2-8.4.4, Tables 8.12-8.13, Figs. 8.23-8.26): the class A
# front of each seat that examples/ch8_optimise.sh wrote to OUT (default ./out/ch8)
# re-simulated on classes B and C (each at its own speed over 1000 m, as configs/ch8/<seat>_
# class_{b,c}.yaml drive them; and with the class alone changed, `--road B --road C`: same
# speed and realisation), with the passenger 20 kg lighter and heavier, and the STHT of
# the front's edges and knee with the Table 2.3 passenger: OUT/<seat>_roads.{h5,png},
# OUT/<seat>_masses.{h5,png} and OUT/<seat>_front_stht.{h5,png}. SUSPOPT_QUICK=1 shortens
# the runs on the other roads to 3 s (examples/budget_config.sh), e.g. in CI.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:-out/ch8}"
run() { "$here/examples/budget_config.sh" "$here/configs/ch8/$1.yaml" "$out/configs"; }
for seat in ps nss1 nss2 nss3 nss4; do
    front="$out/pareto_${seat}_class_a.h5"
    echo "== $seat: roads B and C"
    suspopt analyse roads "$front" --road "$(run "${seat}_class_b")" \
        --road "$(run "${seat}_class_c")" --road B --road C \
        -o "$out/${seat}_roads.h5" --plot "$out/${seat}_roads.png"
    echo "== $seat: passenger -20 kg and +20 kg"
    suspopt analyse masses "$front" -o "$out/${seat}_masses.h5" --plot "$out/${seat}_masses.png"
    echo "== $seat: STHT of the edges and knee"
    suspopt analyse transmissibility "$front" \
        --with "$(run "${seat}_class_a_passenger")" \
        -o "$out/${seat}_front_stht.h5" --plot "$out/${seat}_front_stht.png"
done
