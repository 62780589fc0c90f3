#!/usr/bin/env bash
# Fails (exit 1, naming each file and line) when a tracked C++ file differs from the repository's
# .clang-format. CTest runs it as the `format` test, so CI and the README's test command check it.
# To fix: git ls-files '*.cpp' '*.h' | xargs clang-format -i
set -euo pipefail
cd "$(dirname "$0")/.."
if git rev-parse --is-inside-work-tree > /dev/null 2>&1; then
  mapfile -t files < <(git ls-files '*.cpp' '*.h')
else  # an exported tree (git archive): every source outside build folders
  mapfile -t files < <(find . \( -path './build*' -o -path './.git' \) -prune -o \
                            -type f \( -name '*.cpp' -o -name '*.h' \) -print | sort)
fi
clang-format --dry-run --Werror "${files[@]}"
echo "format: ${#files[@]} files match .clang-format"
