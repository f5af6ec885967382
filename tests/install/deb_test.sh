#!/usr/bin/env bash
# Install.DebianPackageHoldsTheInstallTreeAndRunsExtracted: `cpack -G DEB` in the build makes
# vrflow_<version>_<arch>.deb whose Depends come from dpkg-shlibdeps and whose files are the
# install tree under /usr; extracted into a temporary root (never installed system-wide), its
# `vrflow` validates with the packaged node packages and runs a network.
source "$(dirname "$0")/common.sh"
version=$(sed -n 's/^CMAKE_PROJECT_VERSION:STATIC=//p' "$VRFLOW_BUILD_DIR/CMakeCache.txt")
deb=$WORK/out/vrflow_${version}_$(dpkg --print-architecture).deb

(cd "$VRFLOW_BUILD_DIR" && cpack -G DEB -B "$WORK/out") >"$WORK/cpack.log" 2>&1 ||
  fail "cpack -G DEB: $(tail -20 "$WORK/cpack.log")"
expect_file "$deb"

[ "$(dpkg-deb -f "$deb" Package)" = vrflow ] || fail "the package is not named vrflow"
depends=$(dpkg-deb -f "$deb" Depends)
for library in libc6 libstdc++6 libxxhash0 libsodium23 libpugixml1v5; do
  [[ "$depends" == *"$library"* ]] || fail "Depends lacks $library: $depends"
done

dpkg-deb -c "$deb" | awk '{print $6}' >"$WORK/contents"
for file in ./usr/bin/vrflow ./usr/bin/vrflow-daemon ./usr/bin/vrflow-core-points \
  ./usr/lib/libvrflow_module.so.0 ./usr/lib/libvrflow_daemon.so.0 \
  ./usr/include/vrflow/module/module.hpp ./usr/share/vrflow/packages/core/vrflow-package.xml \
  ./usr/share/vrflow/schema/vrflow-package.xsd ./usr/lib/cmake/vrflow/vrflowConfig.cmake \
  ./usr/lib/pkgconfig/vrflow.pc; do
  grep -qxF "$file" "$WORK/contents" || fail "the .deb lacks $file"
done
if grep -q '^./usr/include/vrflow/run/' "$WORK/contents"; then fail "the .deb holds internal headers"; fi
# The Python package goes where Debian's python3 looks under /usr: /usr/lib/python3/dist-packages.
if grep -q '^VRFLOW_PYTHON:BOOL=ON' "$VRFLOW_BUILD_DIR/CMakeCache.txt" &&
  /usr/bin/python3 -c 'import sysconfig, sys; sys.exit("deb_system" not in sysconfig.get_scheme_names())'; then
  grep -qxF ./usr/lib/python3/dist-packages/vrflow/app.py "$WORK/contents" ||
    fail "the .deb lacks ./usr/lib/python3/dist-packages/vrflow/app.py: $(grep -m3 'vrflow/app.py' "$WORK/contents")"
fi

dpkg-deb -x "$deb" "$WORK/root"
R=$WORK/root/usr
mkdir -p "$WORK/run" && cd "$WORK/run"
"$R/bin/vrflow" validate "$VRFLOW_SOURCE_DIR/examples/paper_scene/paper_scene_fluid_blocks.xml" ||
  fail "the extracted vrflow does not validate paper_scene_fluid_blocks.xml"
"$R/bin/vrflow" run "$VRFLOW_SOURCE_DIR/examples/pipeline/pipeline.xml" -n 20 --no-progress \
  --report report.json >run.log 2>&1 || fail "the extracted vrflow run: $(tail -5 run.log)"
expect_report_ok report.json 20
if ldd "$R/bin/vrflow" | grep vrflow | grep -v "$R/bin/../lib/"; then
  fail "the extracted vrflow loads a vrflow library from outside the extracted tree"
fi
echo "ok"
