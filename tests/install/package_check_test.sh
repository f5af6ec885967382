#!/usr/bin/env bash
# Install.PackageManifestIsCheckedWhenItsModuleIsBuilt: vrflow_add_package (from the installed
# vrflow) stops the build on a manifest that the package schema refuses or that names an
# executable the package does not build, naming the manifest's file:line; a right one builds.
source "$(dirname "$0")/common.sh"
install_relocated "$WORK/first" "$WORK/prefix"
P=$WORK/prefix
EXAMPLE=$VRFLOW_SOURCE_DIR/examples/minimal_module

mkdir -p "$WORK/project"
cp "$EXAMPLE/pull_to_origin.cpp" "$WORK/project/"
cat >"$WORK/project/CMakeLists.txt" <<'CMAKE'
cmake_minimum_required(VERSION 3.25)
project(checked LANGUAGES CXX)
find_package(vrflow 0.1 REQUIRED)
vrflow_add_module(vrflow-example-pull-to-origin SOURCES pull_to_origin.cpp)
vrflow_add_package(example MANIFEST vrflow-package.xml MODULES vrflow-example-pull-to-origin)
CMAKE
cmake -S "$WORK/project" -B "$WORK/build" -G Ninja -DCMAKE_PREFIX_PATH="$P" >"$WORK/configure.log" 2>&1 ||
  fail "configure: $(tail -20 "$WORK/configure.log")"

build_package() {  # builds the manifest check only; its output in $WORK/check.log
  cmake --build "$WORK/build" --target vrflow-package-example >"$WORK/check.log" 2>&1
}

# An executable that no module of the package builds (line 3 of the manifest).
sed 's/executable="vrflow-example-pull-to-origin"/executable="vrflow-example-pull"/' \
  "$EXAMPLE/vrflow-package.xml" >"$WORK/project/vrflow-package.xml"
build_package && fail "the build accepted an executable that the package does not build"
grep -q "vrflow-package.xml:3: error: executable 'vrflow-example-pull' is not built by package 'example'" \
  "$WORK/check.log" || fail "the error does not name file:line and the executable: $(cat "$WORK/check.log")"
expect_no_file "$WORK/build/share/vrflow/packages/example/vrflow-package.xml"

# A manifest the schema refuses (an unknown module kind).
sed 's/kind="interactor"/kind="interacter"/' "$EXAMPLE/vrflow-package.xml" >"$WORK/project/vrflow-package.xml"
build_package && fail "the build accepted a manifest that the schema refuses"
grep -q "vrflow-package.xml:3: .*interacter" "$WORK/check.log" ||
  fail "the schema error does not name file:line: $(cat "$WORK/check.log")"

# The right manifest: checked and placed in the build's layout.
cp "$EXAMPLE/vrflow-package.xml" "$WORK/project/"
build_package || fail "the right manifest was refused: $(cat "$WORK/check.log")"
expect_file "$WORK/build/share/vrflow/packages/example/vrflow-package.xml"
echo "ok"
