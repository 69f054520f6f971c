#!/usr/bin/env bash
# Builds the rest of the tree tools/setup.sh configured (tests, studies, benchmarks: setup.sh builds
# only the program and the Python module the demo needs), runs the whole test suite, then the checking
# jobs of issue 12, each in its own build dir (configured in place, incremental on a second run):
#  - fuzz + sanitizer (build-fuzz/, clang with ASan + UBSan, libFuzzer): by default the calib
#    readers' fuzz targets (CSV tables; camera, rig and line-camera YAML; other tools' camera
#    files, the certificate's JSON documents) for AEROCAL_FUZZ_SECONDS (20 s) each, and the calib
#    tests labelled `reader` (every reader and writer of files in calib) under the same sanitizers;
#  - AEROCAL_FULL_CHECKS=1 adds every fuzz target (block files, stitching CSV, importers, stitch
#    result JSON, rig project and rig inputs, pushbroom inputs, the budget YAML and the directions
#    file, the readers inside the command line: --groups, certificate files, rig stitch, pushbroom
#    control, the batch manifest) and the whole
#    sanitizer job (build-asan/, gcc -fsanitize=address,undefined): every
#    test labelled `unit` and the bad-input CLI cases (tools/bad_input runs the sanitized aerocal).
#    That instruments all three libraries (12.5 min on 2 cores for the clang build), too much for
#    the 30-minute CI budget, hence off by default (README "Checking jobs").
# AEROCAL_FUZZ=0 skips fuzzing and the sanitized reader tests. Idempotent: nothing is installed here.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
jobs="$(nproc)"
full="${AEROCAL_FULL_CHECKS:-0}"

cmake --build "$root/build" -j"$jobs"

# Tests labelled `long` (multi-flight studies) are for benchmarks and local checks, not CI:
# AEROCAL_LONG=1 runs them too.
if [ "${AEROCAL_LONG:-0}" = 1 ]; then
  ctest --test-dir "$root/build" --output-on-failure -j"$jobs"
else
  ctest --test-dir "$root/build" --output-on-failure -j"$jobs" -LE long
fi

# `ctest -N` names of the tests matching the ctest arguments, as their build targets.
test_targets() {
  ctest --test-dir "$1" -N "${@:2}" | sed -n 's/^ *Test *#[0-9]*: *//p' | sed 's|/|_|g'
}

export ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
if [ "${AEROCAL_FUZZ:-1}" = 1 ]; then
  CXX=clang++ cmake -S "$root" -B "$root/build-fuzz" -DCMAKE_BUILD_TYPE=Release \
    -DAEROCAL_BUILD_FUZZERS=ON -DAEROCAL_BUILD_TESTS=ON >/dev/null
  # fuzz/camera_formats reaches every registered format (the tool layer's OpenCV FileStorage
  # reader compiled in); fuzz/json_schema the certificate's input documents (issue 37).
  fuzzers='fuzz/(csv|camera_yaml|camera_formats|json_schema)'
  [ "$full" = 1 ] && fuzzers='fuzz/[a-z_]+'
  # Beside the fuzzers, the tests labelled `reader` (the calib readers and writers of files: CSV,
  # YAML, JSON, the other tools' camera files, image metadata, output sets) under the same
  # sanitizers. The calib math tests (residuals, solver, conversions) are left to the main suite
  # and to the full job's gcc sanitizer run: under ASan + UBSan + coverage their autodiff code
  # runs about 70x slower (one camera conversion: 0.84 s -> 62 s), for no input read. One build,
  # one ctest run: the longest sanitized test (calib/camera_formats, ~90 s, as its writers fit
  # cameras; started first by its COST) shares the two cores with the fuzzers.
  checks=(-L 'fuzz|reader' -R "^(${fuzzers}|calib/[a-z_]+|tools/output_set)\$")
  mapfile -t targets < <(test_targets "$root/build-fuzz" "${checks[@]}" | sed '/^fuzz_/!s/^/test_/')
  cmake --build "$root/build-fuzz" -j"$jobs" --target "${targets[@]}"
  ctest --test-dir "$root/build-fuzz" --output-on-failure -j"$jobs" "${checks[@]}"
fi

if [ "$full" = 1 ]; then
  cmake -S "$root" -B "$root/build-asan" -DCMAKE_BUILD_TYPE=Release -DAEROCAL_SANITIZE=ON >/dev/null
  # (architecture/module_boundaries is a script, no target)
  mapfile -t targets < <(test_targets "$root/build-asan" -L unit | grep -v '^architecture_' | sed 's/^/test_/')
  cmake --build "$root/build-asan" -j"$jobs" --target aerocal test_tools_bad_input "${targets[@]}"
  ctest --test-dir "$root/build-asan" --output-on-failure -j"$jobs" -L unit
  ctest --test-dir "$root/build-asan" --output-on-failure -R '^tools/bad_input$'
fi
