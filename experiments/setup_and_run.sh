#!/usr/bin/env bash
# kerf on a fresh Debian 12 machine: install what is missing, configure, build, then either run
# the default job or the whole test suite. Used by the README's two commands and by .ci/run.
#
#   bash experiments/setup_and_run.sh default   # build, then the default job
#   bash experiments/setup_and_run.sh test      # build, then every test through ctest
#   bash experiments/setup_and_run.sh asan      # AddressSanitizer + UBSan build (build-asan), every test
#   bash experiments/setup_and_run.sh asan-ci   # CI's sanitizer stage: the same build without the
#                                               # benchmarks, every test but the long runs listed in
#                                               # tests/sanitizer_long_runs.txt (docs/reliability.md)
set -euo pipefail
job="${1:-default}"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${KERF_BUILD_DIR:-$here/build}"

# Debian packages kerf builds and tests with (DESIGN.md, "Libraries").
packages=(cmake g++ make pkg-config git
          libeigen3-dev libgmsh-dev libvtk9-dev libtomlplusplus-dev libcli11-dev nlohmann-json3-dev
          libssl-dev libgtest-dev libbenchmark-dev python3-matplotlib
          libdeal.ii-dev libopenblas0-pthread openmpi-bin clang-14 libclang-rt-14-dev libsuitesparse-dev
          xvfb xauth libgl1-mesa-dri ccache lld)
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

build_type=Release
options=()
if [ "$job" = asan ] || [ "$job" = asan-ci ]; then # docs/reliability.md: flags, run-time options, the leak suppressions
  build="${KERF_BUILD_DIR:-$here/build-asan}"
  build_type=Asan
  # the benchmarks are no tests: CI's stage does not build them
  if [ "$job" = asan-ci ]; then options=(-DKERF_BENCHMARKS=OFF); fi
fi
# The default job needs the two programs only (kerf, kerf-rig, and what they link): a newcomer sees results
# without first compiling the tests and benchmarks; the test jobs build everything.
targets=()
if [ "$job" = default ]; then targets=(--target kerf kerf-rig); fi
cmake -S "$here" -B "$build" -DCMAKE_BUILD_TYPE=$build_type "${options[@]}"
cmake --build "$build" -j2 "${targets[@]}"

case "$job" in
  default)
    cd "$here"
    "$build/apps/kerf/kerf" mesh potato_rect_cut
    "$build/apps/kerf/kerf" run potato_rect_cut --model fracture
    "$build/apps/kerf/kerf" study default
    ;;
  test)
    cd "$build"
    ctest -j2 --output-on-failure --timeout 900
    ;;
  asan|asan-ci)
    cd "$build"
    export ASAN_OPTIONS="detect_leaks=1:strict_string_checks=1:check_initialization_order=1"
    export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
    export LSAN_OPTIONS="suppressions=$here/cmake/lsan_suppressions.txt:print_suppressions=0"
    exclude=()
    if [ "$job" = asan-ci ]; then
      # One ctest regular expression from the list's first column (comments and blank lines skipped).
      long_runs="$(sed -e 's/#.*//' -e 's/[[:space:]]*$//' "$here/tests/sanitizer_long_runs.txt" | grep -v '^$' | paste -sd '|')"
      [ -n "$long_runs" ] && exclude=(-E "$long_runs")
    fi
    ctest -j2 --output-on-failure --timeout 2700 "${exclude[@]}"
    ;;
  *)
    echo "usage: $0 default|test|asan|asan-ci" >&2
    exit 64
    ;;
esac
