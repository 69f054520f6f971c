#!/usr/bin/env bash
# Runs the whole test suite of an already built tree (tools/setup.sh builds it).
set -euo pipefail
cd "$(dirname "$0")/../build"
ctest --output-on-failure -j"$(nproc)"
