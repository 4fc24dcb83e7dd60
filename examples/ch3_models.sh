#!/usr/bin/env bash
# Chapter 3 comparison of vehicle models, run as a CI job would: every config through the CLI,
# one HDF5 file each in OUT (default ./out/ch3).
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:-out/ch3}"
mkdir -p "$out"
for cfg in "$here"/configs/ch3/*.yaml; do
    name="$(basename "$cfg" .yaml)"
    echo "== $name"
    suspopt simulate "$cfg" -o "$out/$name.h5"
done
