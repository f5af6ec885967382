#!/bin/bash
# Runs the vrflow-fluid-blocks of several builds alternately on one case, so that old and new
# see the same machine load (the fluid's regression hunt of 2026-11-27: builds of older commits
# made in a scratch worktree). One JSON line per run: the build's name, the round, the 1/5/15-min
# load averages when it started, and the program's own line.
#   bench/fluid/alternate.sh ROUNDS NAME=BINDIR [NAME=BINDIR ...] -- [vrflow-fluid-blocks flags]
# The flags default to the benchmark's small grid on one core (--serial, 32 x 64 x 32, dt 0.005,
# 3 warm-up steps, 30 timed); flags given are appended (e.g. --bodies 20). Flags an older build
# does not know make its run fail (a line with "failed").
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
for b in "${builds[@]}"; do
  if [ ! -x "${b#*=}/vrflow-fluid-blocks" ]; then
    echo "$0: no program ${b#*=}/vrflow-fluid-blocks" >&2
    exit 2
  fi
done
for r in $(seq "$rounds"); do
  for b in "${builds[@]}"; do
    load=$(cut -d' ' -f1-3 /proc/loadavg)
    out=$("${b#*=}/vrflow-fluid-blocks" --serial --nx 32 --ny 64 --nz 32 --h 0.03125 --dt 0.005 \
      --warmup 3 --steps 33 --max-particles 2000000 "$@" 2>&1 | grep '^{')
    [ -n "$out" ] || out='{"failed":true}'
    echo "{\"code\":\"${b%%=*}\",\"round\":$r,\"load_at_start\":\"$load\",\"result\":$out}"
  done
done
