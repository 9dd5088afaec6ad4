#!/usr/bin/env bash
# Regenerates the viewer's pictures in docs/pictures/ (shown by README.md and docs/viewer.md) with
# `kerf view --screenshot`, off screen: under the X display in DISPLAY, else under a private Xvfb
# (xvfb-run). Never edit the pictures by hand; rerun this script.
#
#   bash experiments/viewer/make_pictures.sh            # build/apps/kerf/kerf
#   KERF=/path/to/kerf bash experiments/viewer/make_pictures.sh
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
kerf="${KERF:-$here/build/apps/kerf/kerf}"
out="$here/docs/pictures"
runs="${RUNS_DIR:-$here/runs/pictures}"
mkdir -p "$out" "$runs"

view() {
  if [ -n "${DISPLAY:-}" ]; then "$kerf" view "$@"
  else xvfb-run -a -s "-screen 0 1600x1200x24" "$kerf" view "$@"; fi
}
size=(--width 960 --height 640)

# Runs, then pictures of them at a time (the spring network's own series when the run wrote one,
# else the model re-stepped through the run's samples), and one live-view picture stepped off line.
"$kerf" run clay_pull --model springs -o "$runs/clay_pull/springs"
"$kerf" run clay_tear --model springs -o "$runs/clay_tear/springs"
"$kerf" run clay_cut_apart --model edge -o "$runs/clay_cut_apart/edge"
view "$runs/clay_pull/springs" --at 1.6 --no-chart "${size[@]}" --screenshot "$out/clay_pull_springs.png"
view "$runs/clay_tear/springs" --at 3 --no-chart "${size[@]}" --screenshot "$out/clay_tear_springs.png"
view "$runs/clay_cut_apart/edge" --at 3.8 --no-chart "${size[@]}" --screenshot "$out/clay_cut_apart_edge.png"
view sponge_cut_constant --model voxel --at 1.2 "${size[@]}" --screenshot "$out/sponge_cut_voxel.png"
view potato_rect_cut --model fracture --at 8 "${size[@]}" --screenshot "$out/potato_rect_cut_fracture.png"

# Replay side by side: the reference's fields beside the spring network's embedded mesh, both
# coloured by von Mises stress on one scale, with the force-displacement chart below.
"$kerf" reference clay_pull --samples 20 -o "$runs/clay_pull/reference"
view "$runs/clay_pull/reference" "$runs/clay_pull/springs" --colour von-mises --at 1.6 --width 1280 --height 800 \
  --screenshot "$out/clay_pull_reference_vs_springs.png"
echo "pictures in $out"
