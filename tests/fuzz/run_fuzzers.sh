#!/usr/bin/env bash
# Builds the libFuzzer targets with clang and runs each for a short, bounded time on its seed
# corpus. Usage: run_fuzzers.sh SOURCE_DIR BUILD_DIR SECONDS
set -euo pipefail
src=$1 build=$2 seconds=$3
if ! command -v clang++ >/dev/null; then
  echo "clang++ not found: fuzz targets need clang (make deps installs it)" >&2
  exit 1
fi
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
cmake -S "$src/tests/fuzz/standalone" -B "$build" -G Ninja -DCMAKE_CXX_COMPILER=clang++ "${launcher[@]}" \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
# A failed build shows its log (the fuzz run would otherwise fail without a word).
cmake --build "$build" >"$build/build.log" 2>&1 || { cat "$build/build.log" >&2; exit 1; }
for target in message_reader app_loader composite_loader frame_reader control_channel \
  recording_reader; do
  corpus=$(mktemp -d)
  cp "$src"/tests/fuzz/corpus/${target%%_*}/* "$corpus"/ 2>/dev/null || true
  echo "fuzzing $target for ${seconds}s"
  "$build/fuzz_$target" -max_total_time="$seconds" -rss_limit_mb=2048 -max_len=65536 \
    -print_final_stats=1 "$corpus" 2>&1 | tail -n 12
  rc=${PIPESTATUS[0]}
  rm -rf "$corpus"
  [ "$rc" -eq 0 ] || { echo "fuzzer $target found a problem" >&2; exit 1; }
done
