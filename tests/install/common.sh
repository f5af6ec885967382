# Shared by the install tests (sourced): a temporary folder removed at exit, a home of its own,
# and helpers that fail with a message naming what was checked. Needs VRFLOW_BUILD_DIR and
# VRFLOW_SOURCE_DIR (tests/install/CMakeLists.txt sets both).
set -euo pipefail

: "${VRFLOW_BUILD_DIR:?}" "${VRFLOW_SOURCE_DIR:?}"
# Out-of-tree builds reuse the user's compiler cache when there is one (found before HOME moves).
if command -v ccache >/dev/null; then
  CCACHE_DIR=${CCACHE_DIR:-$(ccache -k cache_dir)}
  export CCACHE_DIR CCACHE_BASEDIR=${CCACHE_BASEDIR:-$VRFLOW_SOURCE_DIR} CCACHE_NOHASHDIR=1
  CMAKE_LAUNCHER=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
else
  CMAKE_LAUNCHER=()
fi
WORK=$(mktemp -d "${TMPDIR:-/tmp}/vrflow-install-test.XXXXXX")
trap 'rm -rf "$WORK"' EXIT
export HOME=$WORK/home XDG_RUNTIME_DIR=$WORK/runtime XDG_STATE_HOME=$WORK/state
mkdir -p "$HOME" "$XDG_RUNTIME_DIR" "$XDG_STATE_HOME"
chmod 700 "$XDG_RUNTIME_DIR"
unset VRFLOW_PACKAGE_PATH VRFLOW_FILTER_PATH VRFLOW_COMPOSITE_PATH

fail() {
  echo "FAILED: $*" >&2
  exit 1
}

expect_file() {
  [ -e "$1" ] || fail "expected $1"
}

expect_no_file() {
  [ ! -e "$1" ] || fail "did not expect $1"
}

# Installs the current build into $1 and moves it to $2: what follows uses the moved tree, so the
# tests also show that an installed tree is relocatable.
install_relocated() {
  cmake --install "$VRFLOW_BUILD_DIR" --prefix "$1" >"$WORK/install.log" ||
    fail "cmake --install $VRFLOW_BUILD_DIR --prefix $1 (log: $(tail -5 "$WORK/install.log"))"
  mv "$1" "$2"
}

# The JSON report $1 says the run ended well, after $2 iterations of each module.
expect_report_ok() {
  grep -q '^  "status": "ok",$' "$1" || fail "report $1: the run did not end well: $(head -8 "$1")"
  awk -v n="$2" '/^      "iterations": / { modules++; if ($2 != n ",") wrong++ }
    END { exit !(modules > 0 && wrong == 0) }' "$1" ||
    fail "report $1: not every module ran $2 iterations"
}

# The oscillator's CSV $1 follows x(t) = x0 cos(2 t) (examples/minimal_module/README.md).
expect_oscillation() {
  awk -F, 'NR > 1 { x0 = (NR - 2) % 3; d = $7 - x0 * cos(2 * $4); if (d < 0) d = -d;
             if (d > 5e-3) { print "off at: " $0; bad = 1 }; rows++ }
           END { exit !(rows > 0 && !bad) }' "$1" || fail "$1 does not follow x0 cos(2 t)"
}
