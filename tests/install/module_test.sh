#!/usr/bin/env bash
# Install.OutOfTreeModuleBuildsWithFindPackageAndPkgConfigAndRuns: examples/minimal_module built
# out of tree against the installed prefix only, once with find_package(vrflow) (its CMakeLists)
# and once with pkg-config (one compiler line); each is registered with --packages and runs in
# the oscillator network under the installed `vrflow run`. The CMake build, installed into the
# prefix, is then found with no option.
source "$(dirname "$0")/common.sh"
install_relocated "$WORK/first" "$WORK/prefix"
P=$WORK/prefix
EXAMPLE=$VRFLOW_SOURCE_DIR/examples/minimal_module

run_oscillator() {  # folder, vrflow options...
  mkdir -p "$1" && cd "$1" && shift
  "$P/bin/vrflow" run "$EXAMPLE/oscillator.xml" -n 200 --no-progress --report report.json "$@" \
    >run.log 2>&1 || fail "vrflow run in $PWD: $(tail -5 run.log)"
  expect_report_ok report.json 200
  expect_oscillation oscillator.csv
}

# find_package(vrflow): the example's own CMakeLists, configured on its own.
cmake -S "$EXAMPLE" -B "$WORK/cmake-build" -G Ninja -DCMAKE_PREFIX_PATH="$P" "${CMAKE_LAUNCHER[@]}" \
  >"$WORK/configure.log" 2>&1 || fail "configure with find_package: $(tail -20 "$WORK/configure.log")"
cmake --build "$WORK/cmake-build" >"$WORK/build.log" 2>&1 ||
  fail "build with find_package: $(tail -20 "$WORK/build.log")"
expect_file "$WORK/cmake-build/bin/vrflow-example-pull-to-origin"
expect_file "$WORK/cmake-build/share/vrflow/packages/example/vrflow-package.xml"
if ldd "$WORK/cmake-build/bin/vrflow-example-pull-to-origin" | grep vrflow | grep -v "$P/lib/"; then
  fail "the module links a vrflow library from outside the prefix"
fi
run_oscillator "$WORK/run-cmake" --packages "$WORK/cmake-build/share/vrflow/packages"

# pkg-config: a plain compiler line, the manifest beside the executable in a package folder.
mkdir -p "$WORK/pc-package"
cp "$EXAMPLE/vrflow-package.xml" "$WORK/pc-package/"
# shellcheck disable=SC2046
${CXX:-c++} "$EXAMPLE/pull_to_origin.cpp" -o "$WORK/pc-package/vrflow-example-pull-to-origin" \
  $(PKG_CONFIG_PATH=$P/lib/pkgconfig pkg-config --cflags --libs vrflow) ||
  fail "build with pkg-config"
run_oscillator "$WORK/run-pkg-config" --packages "$WORK/pc-package"

# Installed beside vrflow's own packages, the module is found with no option.
cmake --install "$WORK/cmake-build" --prefix "$P" >/dev/null || fail "install of the example"
expect_file "$P/share/vrflow/packages/example/vrflow-package.xml"
expect_file "$P/bin/vrflow-example-pull-to-origin"
rm -rf "$WORK/cmake-build" "$WORK/pc-package"
run_oscillator "$WORK/run-installed"
echo "ok"
