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
# The rest of the archive's closed meshes (first run 2026-12-05, twenty-first session): copies of
# a shape in other files, formats and vertex orders too (shuffled, .ply, .stl).
more=(beam.off blob-closed.off blobby-shuffled.off bunny00.off cheese-box.off colored_tetra.ply corner_poly.off
      cross_quad.off cube-shuffled.off cube4-shuffled.off cube_poly.off cube_quad.off ellipsoid.off fandisk-box.off
      fandisk_large.off geosphere.off horizons-domain.off itemb.off mpi_triang.off pinion_small.off prim.off
      quint_tris.off reference_tetrahedron.off refined_elephant.off small_cube.off sphere.ply sphere.stl
      sphere966.off tet-shuffled.off translated-cube.off)
mkdir -p more
for m in "${more[@]}"; do
  [ -f "more/$m" ] || tar -xzf data.tar.gz -O "data/meshes/$m" > "more/$m"
done
echo "bench/unseen-data/more: ${#more[@]} meshes"
# Open or split meshes that `--fill-holes --largest-component` makes mappable.
open=(ChineseDragon-10kv blade blobby_3cc bones cylinder double-torus-3-holes elephant-with-holes head holes knot2
      lion-head lion mannequin-devil mech-holes-shark mushroom nefertiti pig three_peaks)
mkdir -p open
for m in "${open[@]}"; do
  [ -f "open/$m.off" ] || tar -xzf data.tar.gz -O "data/meshes/$m.off" > "open/$m.off"
done
echo "bench/unseen-data/open: ${#open[@]} meshes (map them with --fill-holes --largest-component)"
