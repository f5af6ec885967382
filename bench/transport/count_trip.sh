#!/bin/bash
# Counts what a 64-byte message costs between two vrflow daemons over TCP (loopback), in units
# that do not depend on the machine's load: per one-way message, the system calls of each
# thread of the daemons and modules (perf trace -s), the context switches, CPU migrations and
# page faults of the whole run (perf stat). A ping-pong of ROUND_TRIPS round trips (default 5000) between module
# ping (host a, 127.0.0.1) and pong (host b, 127.0.0.2), started with `vrflow launch`.
#   bench/transport/count_trip.sh NAME BINDIR [ROUND_TRIPS] [SIZE]
# BINDIR holds vrflow, vrflow-daemon and vrflow-bench-peer (a build's bin/). One JSON line on
# stdout; the threads' tables on stderr. Needs perf (Debian: linux-perf) and root or
# kernel.perf_event_paranoid <= 1. Start-up system calls (a few hundred) are included.
set -euo pipefail
if [ $# -lt 2 ]; then
  echo "usage: $0 NAME BINDIR [ROUND_TRIPS] [SIZE]" >&2
  exit 2
fi
name=$1 bin=$(realpath "$2") rounds=${3:-5000} size=${4:-64}
for program in vrflow vrflow-daemon vrflow-bench-peer; do
  [ -x "$bin/$program" ] || { echo "$0: no program $bin/$program" >&2; exit 2; }
done
command -v perf >/dev/null || { echo "$0: perf is not installed (Debian: linux-perf)" >&2; exit 2; }
dir=$(mktemp -d /tmp/vrflow-count-trip-XXXXXX)
trap 'rm -rf "$dir"' EXIT
mkdir -p "$dir/packages/bench"
cat > "$dir/packages/bench/vrflow-package.xml" <<XML
<?xml version="1.0" encoding="UTF-8"?>
<package name="bench" version="1">
  <module type="peer" executable="$bin/vrflow-bench-peer" kind="other">
    <doc>Transport benchmark peer.</doc>
    <input name="in" data="any"/>
    <output name="out" data="any"/>
    <param name="role" type="string" default="pong" doc="-"/>
    <param name="size" type="int" default="64" min="0" doc="-"/>
    <param name="warmup" type="int" default="0" min="0" doc="-"/>
    <param name="results" type="file" default="" doc="-"/>
    <param name="count" type="int" default="0" min="0" doc="-"/>
  </module>
</package>
XML
cat > "$dir/pingpong.xml" <<XML
<?xml version="1.0" encoding="UTF-8"?>
<application name="count-trip" version="1">
  <hosts>
    <host id="a" address="127.0.0.1"/>
    <host id="b" address="127.0.0.2"/>
  </hosts>
  <modules>
    <module id="ping" package="bench" type="peer" host="a">
      <param name="role" value="ping"/>
      <param name="size" value="$size"/>
      <param name="results" value="$dir/rtt"/>
      <param name="count" value="$((rounds + 1))"/>
      <input port="in" initial-messages="1"/>
    </module>
    <module id="pong" package="bench" type="peer" host="b">
      <param name="role" value="pong"/>
    </module>
  </modules>
  <connections>
    <connection from="ping.out" to="pong.in"/>
    <connection from="pong.out" to="ping.in"/>
  </connections>
</application>
XML
run=("$bin/vrflow" --packages "$dir/packages" launch "$dir/pingpong.xml" --backend local)
load=$(cut -d' ' -f1-3 /proc/loadavg)
perf stat -x, -e context-switches,cpu-migrations,task-clock,page-faults -o "$dir/stat" -- "${run[@]}" \
  >/dev/null 2>"$dir/err1" || { cat "$dir/err1" >&2; exit 1; }
perf trace -s -o "$dir/trace" -- "${run[@]}" >/dev/null 2>"$dir/err2" || { cat "$dir/err2" >&2; exit 1; }
messages=$((2 * rounds))
# Per thread, per round trip (daemon and module threads with more than one call per 10 round
# trips; calls made less than once per 20 round trips left out), then totals per one-way message.
awk -v n="$messages" -v r="$rounds" '
  /^ [^ ].*\(/ { thread = $1 " " $2; next }
  /^ +[a-z_0-9]+ +[0-9]+ / && thread ~ /vrflow-daemon|vrflow-bench-pe/ {
    calls[thread] += $2; total[$1] += $2
    if ($2 > r / 20) per[thread] = per[thread] sprintf(" %s %.2f", $1, $2 / r)
  }
  END {
    for (t in calls) if (calls[t] > r / 10) printf "%-28s%s\n", t, per[t] > "/dev/stderr"
    sep = ""; all = 0
    for (s in total) { all += total[s]; if (total[s] > n / 50) { out = out sep sprintf("\"%s\":%.3f", s, total[s] / n); sep = "," } }
    printf "{%s,\"all\":%.3f}", out, all / n
  }' "$dir/trace" > "$dir/syscalls"
cs=$(awk -F, -v n="$messages" '$3 == "context-switches" { printf "%.3f", $1 / n }' "$dir/stat")
mig=$(awk -F, -v n="$messages" '$3 == "cpu-migrations" { printf "%.3f", $1 / n }' "$dir/stat")
faults=$(awk -F, -v n="$messages" '$3 == "page-faults" { printf "%.2f", $1 / n }' "$dir/stat")
cpu=$(awk -F, -v n="$messages" '$3 == "task-clock" { printf "%.1f", $1 * 1000 / n }' "$dir/stat")
median=$(sort -n "$dir/rtt" | awk '{ a[NR] = $1 } END { printf "%.1f", a[int((NR + 1) / 2)] / 2000 }')
echo "{\"code\":\"$name\",\"bytes\":$size,\"round_trips\":$rounds,\"load_at_start\":\"$load\",\"per_one_way_message\":{\"context_switches\":$cs,\"cpu_migrations\":$mig,\"page_faults\":$faults,\"cpu_us\":$cpu,\"syscalls\":$(cat "$dir/syscalls")},\"one_way_us_median_under_perf_stat\":$median}"
