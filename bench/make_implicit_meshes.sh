#!/usr/bin/env bash
# Builds bench/implicit_meshes.cpp and writes its 20 shapes into bench/implicit-data/ (not
# committed): closed meshes of implicit surfaces no one tuned polycube on (first run 2026-12-06,
# twenty-ninth session: 13 shapes; 7 more in the thirtieth). bench/unseen.md has their results:
#   python3 bench/map_bench.py --output FILE bench/implicit-data/*.off
#   python3 bench/quad_bench.py --output FILE bench/implicit-data/*.off
set -euo pipefail
cd "$(dirname "$0")"
mkdir -p implicit-data
g++ -O2 -std=c++17 implicit_meshes.cpp -o implicit-data/implicit_meshes -lgmp -lmpfr
# name and the mesher's ball radius (the sizes of the first run)
shapes=("spring 0.06" "tightspring 0.05" "hook 0.05" "needle 0.03" "bumpy 0.04" "thinring 0.04" "crossrings 0.05"
        "blob3 0.05" "plate4 0.06" "plate16 0.05" "sheet 0.04" "neargap 0.05" "gyroid 0.035"
        "knot25 0.07" "roundcube 0.05" "drilledcube 0.04" "spiky 0.03" "octopus 0.03" "bowl 0.03" "linked 0.04")
for s in "${shapes[@]}"; do
  set -- $s
  implicit-data/implicit_meshes "$1" "$2" "implicit-data/$1.off"
done
