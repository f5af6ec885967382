#!/bin/bash
# The paper scene with its fluid (examples/paper_scene/paper_scene_fluid.xml without its viewer),
# run headless by several builds alternately, so that before and after see the same machine load.
# Each build runs its own source tree's example (the scene as that build shipped it) with its own
# `vrflow run`. One JSON line per run: the build, the round, the load average, the wall time of
# N1 and of N2 iterations, the iterations per second between them (start-up taken out), and the
# CPU seconds of every process of the longer run (children of `vrflow run` included). A build may
# name parameters to set for its runs after a second colon, comma-separated (`vrflow run --set`),
# so one build can also be compared with itself under other settings.
#   bench/scene/paper_fluid_alternate.sh ROUNDS N1 N2 NAME=SOURCE:BINDIR[:SETS] [...]
# e.g. bench/scene/paper_fluid_alternate.sh 3 30 130 before=/work/base:/work/base/build/bin \
#        after=.:build/bin two-threads=.:build/bin:water.threads=2
set -u
if [ $# -lt 4 ]; then
  echo "usage: $0 ROUNDS N1 N2 NAME=SOURCE:BINDIR[:SETS] [NAME=SOURCE:BINDIR[:SETS] ...]" >&2
  exit 2
fi
rounds=$1 n1=$2 n2=$3
shift 3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
builds=()
for b in "$@"; do
  name=${b%%=*} rest=${b#*=}
  source=${rest%%:*} bin=${rest#*:}
  sets=""
  if [ "${bin#*:}" != "$bin" ]; then
    sets=${bin#*:} bin=${bin%%:*}
  fi
  if [ ! -x "$bin/vrflow" ] || [ ! -f "$source/examples/paper_scene/paper_scene_fluid.xml" ]; then
    echo "$0: $name: no $bin/vrflow or $source/examples/paper_scene/paper_scene_fluid.xml" >&2
    exit 2
  fi
  # The example's folder (relative files such as scene.json), its viewer and state files removed.
  mkdir -p "$work/$name"
  cp -r "$source/examples/paper_scene/." "$work/$name/"
  python3 - "$work/$name/paper_scene_fluid.xml" <<'EOF' || exit 2
import sys
import xml.etree.ElementTree as ET
path = sys.argv[1]
tree = ET.parse(path)
root = tree.getroot()
viewers = set()
for modules in root.iter("modules"):
    for m in list(modules):
        if m.tag == "module" and m.get("package") == "viewer":
            viewers.add(m.get("id"))
            modules.remove(m)
for m in root.iter("module"):
    for p in list(m):
        if p.tag == "param" and p.get("name") == "state-file":
            m.remove(p)
for connections in root.iter("connections"):
    for c in list(connections):
        ends = (c.get("from", "").split(".")[0], c.get("to", "").split(".")[0])
        if any(e in viewers for e in ends):
            connections.remove(c)
tree.write(path)
EOF
  builds+=("$name=$(cd "$bin" && pwd):$sets")
done
# Wall seconds and CPU seconds (user + system of the run and all its children) of one run.
run() {
  local bin=$1 file=$2 n=$3 sets=$4
  python3 - "$bin/vrflow" "$file" "$n" "$sets" <<'EOF'
import os, resource, subprocess, sys, time
vrflow, app, n, sets = sys.argv[1:5]
extra = [a for s in sets.split(",") if s for a in ("--set", s)]
t0 = time.monotonic()
r = subprocess.run([vrflow, "run", app, "-n", n, "--no-progress"] + extra, stdout=subprocess.DEVNULL,
                   stderr=subprocess.PIPE, text=True, cwd=os.path.dirname(app))
wall = time.monotonic() - t0
usage = resource.getrusage(resource.RUSAGE_CHILDREN)
if r.returncode != 0:
    sys.stderr.write(r.stderr[-2000:])
    print("fail 0 0")
else:
    print("ok %.4f %.4f" % (wall, usage.ru_utime + usage.ru_stime))
EOF
}
for r in $(seq "$rounds"); do
  for b in "${builds[@]}"; do
    name=${b%%=*} rest=${b#*=}
    bin=${rest%%:*} sets=${rest#*:}
    load=$(cut -d' ' -f1 /proc/loadavg)
    read -r s1 w1 _ < <(run "$bin" "$work/$name/paper_scene_fluid.xml" "$n1" "$sets")
    read -r s2 w2 c2 < <(run "$bin" "$work/$name/paper_scene_fluid.xml" "$n2" "$sets")
    if [ "$s1" != ok ] || [ "$s2" != ok ]; then
      echo "{\"code\":\"$name\",\"round\":$r,\"failed\":true}"
      continue
    fi
    python3 -c "
import json, sys
n1, n2, w1, w2, c2 = $n1, $n2, $w1, $w2, $c2
print(json.dumps({'form': 'paper_scene_fluid.xml without viewer', 'code': '$name', 'round': $r,
                  'set': '$sets',
                  'wall_s_%d' % n1: w1, 'wall_s_%d' % n2: w2,
                  'iterations_per_s': (n2 - n1) / (w2 - w1) if w2 > w1 else None,
                  'cpu_s_%d' % n2: c2, 'load_average': $load}))"
  done
done
