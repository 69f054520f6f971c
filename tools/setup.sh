#!/usr/bin/env bash
# Installs the Debian packages aerocal needs (only those missing) and builds, in Release, what the
# demo needs: the `aerocal` program and the Python module (tools/run_tests.sh builds the tests,
# studies and benchmarks). Idempotent: a second run installs nothing and rebuilds only what changed.
# ccache is used when installed (it is in the package list): a rebuild in another clone is quick.
# Usage: bash tools/setup.sh [build-dir]   (default: build)
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir="${1:-build}"

packages=(cmake make g++ pkg-config
  libceres-dev libeigen3-dev libopencv-dev libgeographiclib-dev libproj-dev libyaml-cpp-dev libcli11-dev
  nlohmann-json3-dev ccache libgtest-dev libgmock-dev libbenchmark-dev libtbb-dev libtiff-dev libtinyxml2-dev zlib1g-dev clang libclang-rt-dev
  clang-format  # the style test (tests/style/check_format.sh, version 14)
  python3 python3-matplotlib python3-numpy poppler-utils
  python3-dev pybind11-dev python3-pytest
  weasyprint  # report.pdf: the HTML report typeset for A4 (tools/report/README.md)
  parallel  # GNU Parallel (2.9 MB installed, with sysstat 1.8 MB): `aerocal batch` shards, tests/tools/cli_batch
  colmap)   # COLMAP 3.8 (16.5 MB more here, no recommends): `import images --match colmap`, import_images_match_test
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "installing: ${missing[*]}"
  sudo_cmd=""
  [ "$(id -u)" -ne 0 ] && sudo_cmd="sudo"
  $sudo_cmd apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" >/dev/null
demo_targets=(aerocal)
help="$(cmake --build "$build_dir" --target help)"
grep -q "^\.\.\. aerocal_python$" <<<"$help" && demo_targets+=(aerocal_python)
cmake --build "$build_dir" -j"$(nproc)" --target "${demo_targets[@]}"
# `import aerocal` for Debian's python3 (tools/python/README.md): the package of this build,
# installed under /usr/local (the interpreter's dist-packages there); idempotent.
if [ -f "$build_dir/python/aerocal/__init__.py" ]; then
  install_cmd=""
  [ "$(id -u)" -ne 0 ] && install_cmd="sudo"
  $install_cmd cmake --install "$build_dir" --component python >/dev/null
fi
