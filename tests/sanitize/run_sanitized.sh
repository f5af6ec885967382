#!/usr/bin/env bash
# Builds the runtime, its modules and the unit/end-to-end tests with a sanitizer (ASAN =
# address + undefined behaviour, TSAN = threads) in a tree of their own, and runs those tests
# there. Warnings are not errors here: GCC 12 reports false maybe-uninitialized warnings in
# libstdc++ under -fsanitize at -O1. Usage: run_sanitized.sh ASAN|TSAN SOURCE_DIR BUILD_DIR
set -euo pipefail
type=$1 src=$2 build=$3
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
cmake -S "$src" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE="$type" -DVRFLOW_BUILD_BENCH=OFF \
  -DVRFLOW_SANITIZER_TESTS=OFF -DVRFLOW_FUZZ_TESTS=OFF -DVRFLOW_EDITOR=OFF -DVRFLOW_NODES=OFF -DVRFLOW_WARNINGS_AS_ERRORS=OFF \
  "${launcher[@]}" >/dev/null
cmake --build "$build" -j "$(nproc)" >/dev/null
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=0
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
export TSAN_OPTIONS=halt_on_error=1:second_deadlock_stack=1
cd "$build"
status=0
ctest --output-on-failure -j "$(nproc)" -L 'runtime|message|app|transport|launcher' || status=$?
if [ "$status" -ne 0 ] && [ -s Testing/Temporary/LastTestsFailed.log ]; then
  # The failures' own output again, last, where a log cut to its tail still shows it.
  echo "=== output of the failed tests (${type}) ==="
  while IFS=: read -r _ name; do
    awk -v name="$name" '
      { t = "Test: " name }
      !on && length($0) >= length(t) && substr($0, length($0) - length(t) + 1) == t { on = 1 }
      on { print }
      on && /^"[^"]*" end time:/ { exit }' Testing/Temporary/LastTest.log | tail -n 80
  done < Testing/Temporary/LastTestsFailed.log
fi
exit "$status"
