#!/bin/bash
# Runs vrflow-bench-transport of several builds alternately, so that old and new see the same
# machine load (each build's bench starts its own vrflow, vrflow-daemon and peers, from its own
# bin/). One JSON line per result: the build's name, the round, the 1/5/15-min load averages
# when that build's run started, and the benchmark's own line.
#   bench/transport/alternate.sh ROUNDS NAME=BINDIR [NAME=BINDIR ...] -- [flags]
# The flags default to the TCP comparison of issue 25: --transport raw-tcp,zeromq-tcp,vrflow-tcp
# --sizes 64,16M; flags given replace them. A failed run gives a line with "failed".
set -u
if [ $# -lt 2 ]; then
  echo "usage: $0 ROUNDS NAME=BINDIR [NAME=BINDIR ...] -- [flags]" >&2
  exit 2
fi
rounds=$1
shift
builds=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do
  builds+=("$1")
  shift
done
[ $# -gt 0 ] && shift
flags=("$@")
[ ${#flags[@]} -gt 0 ] || flags=(--transport raw-tcp,zeromq-tcp,vrflow-tcp --sizes 64,16M)
for b in "${builds[@]}"; do
  if [ ! -x "${b#*=}/vrflow-bench-transport" ]; then
    echo "$0: no program ${b#*=}/vrflow-bench-transport" >&2
    exit 2
  fi
done
for r in $(seq "$rounds"); do
  for b in "${builds[@]}"; do
    load=$(cut -d' ' -f1-3 /proc/loadavg)
    out=$("${b#*=}/vrflow-bench-transport" "${flags[@]}" 2>/dev/null | grep '^{')
    [ -n "$out" ] || out='{"failed":true}'
    while IFS= read -r line; do
      echo "{\"code\":\"${b%%=*}\",\"round\":$r,\"load_at_start\":\"$load\",\"result\":$line}"
    done <<< "$out"
  done
done
