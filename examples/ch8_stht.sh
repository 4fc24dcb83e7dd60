#!/usr/bin/env bash
# Chapter 8, Analysis 3 (Sec 8.4.4, Fig. 8.26): seat-to-head transmissibility (STHT, Eq 2.86
# with i = head) of one mid-range design of each isolator, PS and NSS1-NSS4, with the Table 2.3
# passenger on the seat, excited by the Table 8.1 quarter car on 1000 m of class A road.
# Writes OUT/<kind>_stht.h5 (linearised and simulated spectra) and OUT/<kind>_stht.png for
# each isolator (default OUT: ./out/ch8). SUSPOPT_QUICK=1 shortens the runs to 3 s
# (examples/budget_config.sh), e.g. in CI.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:-out/ch8}"
mkdir -p "$out"
for kind in ps nss1 nss2 nss3 nss4; do
    echo "== $kind"
    suspopt analyse transmissibility \
        "$("$here/examples/budget_config.sh" "$here/configs/ch8/${kind}_class_a_passenger.yaml" "$out/configs")" \
        -o "$out/${kind}_stht.h5" --plot "$out/${kind}_stht.png"
done
