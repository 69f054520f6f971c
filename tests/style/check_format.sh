#!/bin/sh
# Every C++ source of the tree is formatted by the repository's .clang-format (docs/style.md).
# The formatting rules of clang-format change between major versions: the check runs with
# Debian 12's clang-format 14 (tools/setup.sh installs it) and is skipped, with a message, by
# any other version or without clang-format (exit 77 = skipped for ctest).
# Usage: check_format.sh SOURCE_DIR
cd "$1" || exit 2
command -v clang-format >/dev/null || { echo "SKIPPED: clang-format not installed (apt-get install clang-format)"; exit 77; }
major=$(clang-format --version | sed -n 's/.*version \([0-9]*\).*/\1/p')
[ "$major" = 14 ] || { echo "SKIPPED: clang-format $major, the rules are those of version 14"; exit 77; }
files=$(find calib stitch triangulation tools tests -name '*.cc' -o -name '*.h' | sort)
# shellcheck disable=SC2086  # the file names have no blanks (find above, our own tree)
bad=$(clang-format --dry-run $files 2>&1 | sed -n 's/^\([^:]*\):[0-9]*:[0-9]*: warning:.*/\1/p' | sort -u)
if [ -n "$bad" ]; then
  echo "not formatted (run: clang-format -i FILE):"
  echo "$bad"
  exit 1
fi
echo "$(echo "$files" | wc -l) files formatted"
