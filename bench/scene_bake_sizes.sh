#!/usr/bin/env bash
# Scene bakes of one real scene at growing atlas sizes under one memory limit (issue 16):
# peak RSS (the process's, and at the end of each stage), time per stage, transfer texels/s,
# peak scratch-file bytes and the output's hash (the same bytes before and after a change).
#   bench/scene_bake_sizes.sh VTBAKE SCENE OUTDIR "SIZES_IN_PAGES" [MEMORY_LIMIT] [EXTRA FLAGS]
# e.g. bench/scene_bake_sizes.sh build/release/cli/vtbake \
#        /work/shared/testdata/meshes/scene/VirtualCity/VC.gltf /tmp/sizes "35 69 137" 2G
set -euo pipefail
vtbake=$1 scene=$2 out=$3 sizes=$4 limit=${5:-2G}
shift $(($# < 5 ? $# : 5))
mkdir -p "$out"
printf '%-6s %-13s %9s %9s %9s %9s %9s %9s %10s %12s %12s %9s %s\n' pages atlas unwrap_s \
  transfer_s build_s total_s rss_unw rss_peak covered texels/s/core file_MiB scratch file_xxh
for n in $sizes; do
  json=$out/bake_$n.json
  /usr/bin/time -f '%M' -o "$out/rss_$n" "$vtbake" --json --threads 2 bake "$scene" --size "$n" \
    --memory-limit "$limit" --unwrapped - -o "$out/bake_$n.vtpf" "$@" > "$json" &
  # Scratch bytes: the peak sum of the disk blocks of the bake's open scratch files (unnamed
  # O_TMPFILE files, "DIR/#INODE (deleted)", or unlinked .vtbake-* files, read through /proc;
  # sparse, so blocks, not sizes), sampled every half second.
  python3 - "$!" > "$out/scratch_$n" <<'PY'
import os, sys, time
root = int(sys.argv[1]); peak = 0
def pids():
    out = [root]
    for p in os.listdir("/proc"):
        try:
            if p.isdigit() and int(open("/proc/%s/stat" % p).read().split(")")[1].split()[1]) == root:
                out.append(int(p))
        except OSError:
            pass
    return out
while os.path.exists("/proc/%d" % root):
    total = 0
    for pid in pids():
        try:
            for fd in os.listdir("/proc/%d/fd" % pid):
                path = "/proc/%d/fd/%s" % (pid, fd)
                try:
                    link = os.readlink(path)
                    if "/.vtbake-" in link or ("/#" in link and link.endswith(" (deleted)")):
                        total += os.stat(path).st_blocks * 512
                except OSError:
                    pass
        except OSError:
            pass
    peak = max(peak, total)
    time.sleep(0.5)
print(peak)
PY
  wait
  python3 - "$json" "$out/rss_$n" "$n" "$out/scratch_$n" "$out/bake_$n.vtpf" <<'PY'
import json, sys
j = json.load(open(sys.argv[1])); rss = int(open(sys.argv[2]).read().split()[-1]) * 1024
scratch = int(open(sys.argv[4]).read())
import hashlib
h = hashlib.sha256(open(sys.argv[5], "rb").read()).hexdigest()[:12]
s = j["seconds"]; a = j["atlas"]; t = j["transfer"]; mib = 1 << 20
print("%-6s %-13s %9.1f %9.1f %9.1f %9.1f %8.0fM %8.0fM %10d %12.0f %12.1f %8.2fG %s" % (
    sys.argv[3], "%dx%d" % (a["width"], a["height"]), s.get("unwrap", 0), s.get("transfer", 0),
    s.get("build", 0), j["seconds"]["total"], j["peak_rss_bytes"].get("unwrap", 0) / mib, rss / mib,
    t["covered_texels"], t["texels_per_second"] / 2, j["build"]["bytes"]["file"] / mib,
    scratch / (1 << 30), h))
PY
  rm -f "$out/bake_$n.vtpf"
done
