#!/usr/bin/env bash
# kerf on a fresh Debian 12 machine: install what is missing, configure, build, then either run
# the default job or the whole test suite. Used by the README's two commands and by .ci/run.
#
#   bash experiments/setup_and_run.sh default   # build, then the default job
#   bash experiments/setup_and_run.sh test      # build, then every test through ctest
set -euo pipefail
job="${1:-default}"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${KERF_BUILD_DIR:-$here/build}"

# Debian packages kerf builds and tests with (DESIGN.md, "Libraries").
packages=(cmake g++ make pkg-config git
          libeigen3-dev libgmsh-dev libvtk9-dev libtomlplusplus-dev libcli11-dev nlohmann-json3-dev
          libssl-dev libgtest-dev libbenchmark-dev python3-matplotlib
          libdeal.ii-dev libopenblas0-pthread openmpi-bin)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "kerf: installing ${missing[*]}"
  sudo_cmd=""
  [ "$(id -u)" -ne 0 ] && sudo_cmd="sudo"
  $sudo_cmd apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

cmake -S "$here" -B "$build" -DCMAKE_BUILD_TYPE=Release
cmake --build "$build" -j2

case "$job" in
  default)
    cd "$here"
    "$build/experiments/kerf" mesh potato_rect_cut
    "$build/experiments/kerf" run potato_rect_cut --model fracture
    "$build/experiments/kerf" study default --results-doc docs/results.md
    ;;
  test)
    cd "$build"
    ctest -j2 --output-on-failure --timeout 900
    ;;
  *)
    echo "usage: $0 default|test" >&2
    exit 64
    ;;
esac
