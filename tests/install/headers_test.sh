#!/usr/bin/env bash
# Install.EveryInstalledHeaderCompilesOnItsOwn: each header of the installed SDK compiles alone
# against the prefix and nothing else (vrflow/message/eigen.hpp, Eigen views of the wire's
# arrays, also needs Eigen's own flags, as documented).
source "$(dirname "$0")/common.sh"
install_relocated "$WORK/first" "$WORK/prefix"
P=$WORK/prefix
CXX=${CXX:-c++}
EIGEN_FLAGS=$(pkg-config --cflags eigen3)
export P CXX EIGEN_FLAGS

check_one() {
  extra=""
  [ "$1" = vrflow/message/eigen.hpp ] && extra=$EIGEN_FLAGS
  # shellcheck disable=SC2086
  echo "#include <$1>" | $CXX -std=c++20 -fsyntax-only -Wall -Wextra -Werror -I"$P/include" $extra \
    -x c++ - 2>&1 || { echo "^^^ $1 does not compile on its own"; return 1; }
}
export -f check_one

headers=$(cd "$P/include" && find vrflow -name '*.hpp' | sort)
count=$(echo "$headers" | wc -l)
[ "$count" -ge 30 ] || fail "only $count headers installed"
echo "$headers" | xargs -P "$(nproc)" -I{} bash -c 'check_one {}' || fail "installed headers (above)"
echo "ok: $count headers"
