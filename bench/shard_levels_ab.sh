#!/usr/bin/env bash
# A shard reading the plan's coarser levels (B) against one rebuilding the pyramid (A: the plan.json
# without its "levels" entries, the path before 2026-12-04): same binary, same work folder,
# alternating rounds, shard 0 of N at one thread (docs/BENCHMARKS.md, "Build farm: shards read").
#   bench/shard_levels_ab.sh VTBAKE [SIZE_PAGES=32] [SHARDS=8] [ROUNDS=3]
set -euo pipefail
V=$(readlink -f "$1") size=${2:-32} shards=${3:-8} rounds=${4:-3}
t=$(mktemp -d /tmp/vtbake-shard-ab.XXXXXX)
trap 'rm -rf "$t"' EXIT
$V -q sample-scene $t/scene
b=(bake $t/scene/scene.gltf -o $t/out.vtpf --size $size --work $t/work)
$V -q --threads 2 "${b[@]}" --plan $t/work/plan.json
cp $t/work/plan.json $t/plan.B.json
python3 - "$t" <<'PY'
import json,sys; t=sys.argv[1]; j=json.load(open(t+'/plan.B.json'))
for l in j['layers']: l.pop('levels',None)
json.dump(j,open(t+'/plan.A.json','w'),indent=1)
PY
echo "load before: $(cut -d' ' -f1-3 /proc/loadavg)"
for r in $(seq $rounds); do for v in A B; do
  cp $t/plan.$v.json $t/work/plan.json
  s=$( { /usr/bin/time -f "%e %M" $V --json --threads 1 "${b[@]}" --shard 0/$shards > $t/s.json; } 2>&1 )
  echo "$v round $r: wall/maxrss $s stages $(python3 -c "import json;s=json.load(open('$t/s.json'))['seconds'];print('build %.2f plan %.2f read %.2f' % (s['build'],s['plan'],s['read']))")"
done; done
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
