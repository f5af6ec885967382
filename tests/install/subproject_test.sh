#!/usr/bin/env bash
# Install.SubprojectBuildsAModuleWithoutQtBulletMpiOrOsmesa: a project that adds vrflow's source
# tree with add_subdirectory() builds its own module with vrflow_add_module/vrflow_add_package;
# vrflow, not the top-level project there, searches for none of Qt, Bullet, Open MPI, OSMesa,
# libpng or GoogleTest (its editor, node packages, MPI parts, examples, tests and benchmarks
# default OFF). Only the module's target is built (with ccache when there is one).
source "$(dirname "$0")/common.sh"
# The build folder stays under the build tree, so ccache's base folder covers it.
BUILD=${SUBPROJECT_BUILD_DIR:?}
rm -rf "$BUILD"
trap 'rm -rf "$WORK" "$BUILD"' EXIT
mkdir -p "$WORK/project"
cat >"$WORK/project/CMakeLists.txt" <<CMAKE
cmake_minimum_required(VERSION 3.25)
project(user_modules LANGUAGES CXX)
add_subdirectory($VRFLOW_SOURCE_DIR vrflow)
vrflow_add_module(vrflow-example-pull-to-origin
  SOURCES $VRFLOW_SOURCE_DIR/examples/minimal_module/pull_to_origin.cpp)
vrflow_add_package(example MANIFEST $VRFLOW_SOURCE_DIR/examples/minimal_module/vrflow-package.xml
  MODULES vrflow-example-pull-to-origin)
CMAKE

cmake -S "$WORK/project" -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release "${CMAKE_LAUNCHER[@]}" \
  >"$WORK/configure.log" 2>&1 || fail "configure: $(tail -20 "$WORK/configure.log")"
for option in VRFLOW_EDITOR VRFLOW_NODES VRFLOW_MPI VRFLOW_EXAMPLES VRFLOW_BUILD_TESTS VRFLOW_BUILD_BENCH; do
  grep -qx "$option:BOOL=OFF" "$BUILD/CMakeCache.txt" || fail "$option is not OFF in a subproject"
done
# What a search leaves in the cache: Qt6_DIR, MPI_CXX_*, pkg-config's bullet_/OSMESA_ entries,
# PNG_LIBRARY*, GTest_DIR.
if grep -E '^(Qt6[A-Za-z]*_DIR|MPI_|MPIEXEC|bullet_|OSMESA_|PNG_|GTest_DIR|GVC_)' "$BUILD/CMakeCache.txt"; then
  fail "a subproject searched for what it does not build (above)"
fi
grep -qE 'Qt6|OpenMPI|Bullet|OSMesa' "$WORK/configure.log" && fail "configure output: $(cat "$WORK/configure.log")"

cmake --build "$BUILD" --target vrflow-example-pull-to-origin >"$WORK/build.log" 2>&1 ||
  fail "build: $(tail -20 "$WORK/build.log")"
expect_file "$BUILD/bin/vrflow-example-pull-to-origin"
expect_file "$BUILD/share/vrflow/packages/example/vrflow-package.xml"

# The module runs with the build's vrflow, registered from the project's build tree.
mkdir -p "$WORK/run" && cd "$WORK/run"
"$VRFLOW_BUILD_DIR/bin/vrflow" run "$VRFLOW_SOURCE_DIR/examples/minimal_module/oscillator.xml" -n 200 \
  --no-progress --report report.json --packages "$BUILD/share/vrflow/packages" >run.log 2>&1 ||
  fail "vrflow run: $(tail -5 run.log)"
expect_report_ok report.json 200
expect_oscillation oscillator.csv
echo "ok"
