#!/usr/bin/env bash
# update_bench.sh VTBAKE OUTDIR: the issue-16 update figures on the sample scene. A clean bake,
# an update with nothing changed (time, file untouched), then one texture's texels all halved
# (default scene/leaf_albedo.png: the leaf card's only texture, about 1% of the atlas) and an
# update (time, pages re-encoded), checked byte for byte against a clean bake with --tables-from
# the previous file. CORNER=1 repaints only the texture's top-left 64x64 texels instead;
# BAKE_FLAGS (e.g. "--size 48") go to every bake, for the figure on a larger atlas.
set -euo pipefail
vt=$(readlink -f "$1"); out=$2
rm -rf "$out"; mkdir -p "$out"; cd "$out"
$vt -q sample-scene scene >/dev/null
tex=${TEXTURE:-scene/leaf_albedo.png}
read -r -a flags <<< "${BAKE_FLAGS:-}"
now() { date +%s.%N; }
# The clean bake is a plain one (no band cache written); the first --update, with no output yet,
# is a clean bake that writes the cache (an iterating user's first bake), the same bytes.
t0=$(now); $vt -q --json bake scene/scene.gltf -o plain.vtpf "${flags[@]}" > clean.json; t1=$(now)
$vt -q --json bake scene/scene.gltf -o b.vtpf "${flags[@]}" --update > first.json
cmp plain.vtpf b.vtpf
cp b.vtpf before.vtpf
s0=$(stat -c '%i %Y.%y' b.vtpf)
t2=$(now); $vt -q --json bake scene/scene.gltf -o b.vtpf "${flags[@]}" --update > same.json; t3=$(now)
s1=$(stat -c '%i %Y.%y' b.vtpf)
if [ -n "${CORNER:-}" ]; then oiiotool "$tex" --fill:color=1,0,1 64x64+0+0 -o "$tex"
else oiiotool "$tex" --mulc 0.5 -o "$tex"; fi
t4=$(now); $vt -q --json bake scene/scene.gltf -o b.vtpf "${flags[@]}" --update > update.json; t5=$(now)
$vt -q --json bake scene/scene.gltf -o clean2.vtpf "${flags[@]}" --tables-from before.vtpf > clean2.json
cmp b.vtpf clean2.vtpf && same_bytes=yes || same_bytes=no
python3 - "$t0" "$t1" "$t2" "$t3" "$t4" "$t5" "$same_bytes" "$tex" "$s0" "$s1" <<'PY'
import json, sys
t = [float(x) for x in sys.argv[1:7]]
u = json.load(open("update.json"))["build"]["update"]
c = json.load(open("clean.json"))
st = json.load(open("update.json"))["seconds"]
pages = u["pages_reused"] + u["pages_reencoded"]
print(f"texture changed: {sys.argv[8]}")
print(f"clean bake {t[1]-t[0]:.2f} s  (stages {c['seconds']})")
print(f"unchanged update {t[3]-t[2]:.2f} s, file untouched: {sys.argv[9] == sys.argv[10]}")
print(f"update after change {t[5]-t[4]:.2f} s = {(t[5]-t[4])/(t[1]-t[0]):.3f} of clean (stages {st})")
print(f"pages re-encoded {u['pages_reencoded']} of {pages} = {100*u['pages_reencoded']/pages:.2f}%, "
      f"dropped {u['pages_dropped']}, tables fit {u['tables_fit']:.4f}, full rebuild: {u['full_rebuild']}")
print(f"build stages: clean {c['build']['seconds']}, update {json.load(open('update.json'))['build']['seconds']}")
print(f"update == clean bake --tables-from: {sys.argv[7]}")
PY
