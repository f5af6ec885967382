#!/usr/bin/env bash
# Install.PrefixHoldsTheProgramsLibrariesPackagesAndPublicHeaders: `cmake --install` of the build
# into a prefix, moved elsewhere, holds what docs/install.md lists, only the SDK's public headers,
# and its `vrflow` finds the installed node packages from any folder with no option.
source "$(dirname "$0")/common.sh"
install_relocated "$WORK/first" "$WORK/prefix"
P=$WORK/prefix

for program in vrflow vrflow-daemon vrflow-core-points vrflow-rigid-interactor vrflow-fluid vrflow-viewer; do
  expect_file "$P/bin/$program"
done
for layer in module app net daemon run launcher; do
  expect_file "$P/lib/libvrflow_$layer.so.0"
done
for sdk in module app net daemon; do
  expect_file "$P/lib/libvrflow_$sdk.so"  # the link-time name of what outside code links
done
for package in core rigid massspring viewer fluid; do
  expect_file "$P/share/vrflow/packages/$package/vrflow-package.xml"
done
expect_no_file "$P/share/vrflow/example-packages"
expect_file "$P/share/vrflow/composites/fluid_blocks.vrc.xml"
expect_file "$P/share/vrflow/schema/vrflow-package.xsd"
expect_file "$P/share/vrflow/schema/vrflow-application.xsd"
expect_file "$P/lib/cmake/vrflow/vrflowConfig.cmake"
expect_file "$P/lib/cmake/vrflow/vrflowConfigVersion.cmake"
expect_file "$P/lib/pkgconfig/vrflow.pc"
expect_file "$P/lib/pkgconfig/vrflow-filter.pc"

# Programs and modules find the libraries beside them, wherever the tree is.
for file in "$P/bin/vrflow" "$P/bin/vrflow-core-points"; do
  readelf -d "$file" | grep -q 'R.*PATH.*\[\$ORIGIN/../lib\]' || fail "$file has no \$ORIGIN/../lib RPATH"
  if ldd "$file" | grep 'vrflow' | grep -v "$P/bin/../lib/"; then
    fail "$file loads a vrflow library from outside $P"
  fi
done
readelf -d "$P/lib/libvrflow_module.so.0" | grep -q 'SONAME.*libvrflow_module.so.0' ||
  fail "libvrflow_module has no soname libvrflow_module.so.0"

# Public headers only: the module SDK and the filter SDK, none that says it is internal.
expect_file "$P/include/vrflow/module/module.hpp"
expect_file "$P/include/vrflow/daemon/plugin.hpp"
expect_file "$P/include/vrflow/daemon/testing/filter_harness.hpp"
for layer in net run launcher; do
  expect_no_file "$P/include/vrflow/$layer"
done
if grep -rl 'nternal to vrflow' "$P/include"; then
  fail "internal headers were installed (above)"
fi
for header in $(cd "$VRFLOW_SOURCE_DIR/runtime/include" && grep -rl 'nternal to vrflow' vrflow); do
  expect_no_file "$P/include/$header"
done

# The installed `vrflow` finds the installed packages (rigid, fluid, viewer, core) and
# composites with no option, from a folder that is neither the build nor the prefix.
mkdir -p "$WORK/elsewhere"
cd "$WORK/elsewhere"
"$P/bin/vrflow" validate "$VRFLOW_SOURCE_DIR/examples/paper_scene/paper_scene_fluid_blocks.xml" ||
  fail "the installed vrflow does not validate paper_scene_fluid_blocks.xml"
"$P/bin/vrflow" run "$VRFLOW_SOURCE_DIR/examples/pipeline/pipeline.xml" -n 20 --no-progress \
  --report report.json >run.log 2>&1 || fail "the installed vrflow run: $(tail -5 run.log)"
expect_report_ok report.json 20
echo "ok"
