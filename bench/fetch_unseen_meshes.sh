#!/usr/bin/env bash
# Fetches closed meshes that no test, bench table or tuning here has used before 2026-12-03:
# CGAL's example data from Debian's libcgal-demo package (public data), minus the meshes that
# ../shared/data already holds, into bench/unseen-data/ (not committed). bench/unseen.md is
# `python3 bench/map_bench.py --output bench/unseen.md bench/unseen-data/*.off` over them.
set -euo pipefail
cd "$(dirname "$0")"
meshes=(tetrahedron cube octahedron icosahedron pyramid hedra star tripod cross corner u 3torus P hole mpi
        pipe cactus dragknob part oblong larger_sphere spool pinion hand handle blobby ellipe0.003 cube-meshed
        triceratops retinal dino homer bull rotor_small anchor_dense knot1 turbine camel bear_bis fandisk bear
        man armadillo diplodocus cheese)
mkdir -p unseen-data
cd unseen-data
if [ ! -f data.tar.gz ]; then
  work=$(mktemp -d)
  (cd "$work" && apt-get download libcgal-demo >/dev/null)
  dpkg-deb --fsys-tarfile "$work"/libcgal-demo_*.deb | tar -xO ./usr/share/doc/libcgal-dev/data.tar.gz > data.tar.gz
  rm -rf "$work"
fi
for m in "${meshes[@]}"; do
  [ -f "$m.off" ] || tar -xzf data.tar.gz -O "data/meshes/$m.off" > "$m.off"
done
echo "bench/unseen-data: ${#meshes[@]} meshes"
