#!/usr/bin/env bash
# Install.OutOfTreeFilterPluginBuildsWithFindPackageAndRuns: examples/filter_plugin built out of
# tree with find_package(vrflow) against the installed prefix; the installed `vrflow run` loads it
# (VRFLOW_FILTER_PATH) and keeps one message in five; installed into the prefix, it is found with
# no option.
source "$(dirname "$0")/common.sh"
install_relocated "$WORK/first" "$WORK/prefix"
P=$WORK/prefix
EXAMPLE=$VRFLOW_SOURCE_DIR/examples/filter_plugin

run_every_nth() {  # folder
  mkdir -p "$1" && cd "$1"
  "$P/bin/vrflow" run "$EXAMPLE/every_nth.xml" --no-progress --report report.json >run.log 2>&1 ||
    fail "vrflow run in $PWD: $(tail -5 run.log)"
  counters=$(tail -n +2 every_nth.csv | cut -d, -f7 | tr '\n' ' ')
  [ "$counters" = "0 5 10 15 " ] || fail "every_nth.csv holds counters '$counters', not 0 5 10 15"
}

cmake -S "$EXAMPLE" -B "$WORK/build" -G Ninja -DCMAKE_PREFIX_PATH="$P" "${CMAKE_LAUNCHER[@]}" \
  >"$WORK/configure.log" 2>&1 || fail "configure: $(tail -20 "$WORK/configure.log")"
cmake --build "$WORK/build" >"$WORK/build.log" 2>&1 || fail "build: $(tail -20 "$WORK/build.log")"
expect_file "$WORK/build/lib/vrflow/filters/libvrflow_every_nth.so"

# Not found before it is built or installed: the run fails, naming the plugin.
mkdir -p "$WORK/missing" && cd "$WORK/missing"
if "$P/bin/vrflow" run "$EXAMPLE/every_nth.xml" --no-progress >run.log 2>&1; then
  fail "the run found a plugin that is neither on VRFLOW_FILTER_PATH nor installed"
fi
grep -q 'libvrflow_every_nth.so' run.log || fail "the error does not name the plugin: $(cat run.log)"

VRFLOW_FILTER_PATH=$WORK/build/lib/vrflow/filters run_every_nth "$WORK/run-build"

cmake --install "$WORK/build" --prefix "$P" >/dev/null || fail "install of the plugin"
expect_file "$P/lib/vrflow/filters/libvrflow_every_nth.so"
rm -rf "$WORK/build"
run_every_nth "$WORK/run-installed"
echo "ok"
