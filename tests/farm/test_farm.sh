#!/usr/bin/env bash
# The build farm for real (issue 17): a one-node Slurm cluster (local_cluster.sh), the sample
# scene baked through scripts/farm.sh with 4 shards, one shard killed on purpose on its first
# run; the farm resubmits it alone, that shard merges (the last one to finish does), and the
# merged page file and unwrapped scene are byte-identical to a one-process bake. Stops every daemon it started, by PID. Skips (exit 77) only when the
# Slurm or munge binaries are absent (scripts/setup.sh installs them).
#   tests/farm/test_farm.sh VTBAKE [SOURCE_DIR]
set -euo pipefail
vtbake=$(readlink -f "$1")
src=$(readlink -f "${2:-$(dirname "$0")/../..}")
for tool in munged slurmctld slurmd sbatch squeue scontrol sinfo scancel; do
  if ! command -v "$tool" >/dev/null; then
    echo "SKIP: $tool not found: the farm test needs Slurm and munge (scripts/setup.sh installs slurm-wlm and munge)"
    exit 77
  fi
done
[[ $(id -u) -eq 0 ]] || { echo "test_farm: the one-node cluster runs as root (SlurmUser=root)" >&2; exit 1; }

tmp=$(mktemp -d /tmp/vtbake-farm-test.XXXXXX)
source "$src/tests/farm/local_cluster.sh"
cleanup() {
  stop_cluster
  [[ -n "${VTBAKE_KEEP_TEST_OUTPUT:-}" ]] || rm -rf "$tmp"
}
trap cleanup EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

start_cluster "$tmp/cluster"
echo "cluster up: $(sinfo -h -o '%N %c CPUs %T')"

"$vtbake" -q sample-scene "$tmp/scene" --ground-cells 4 --sphere-segments 12 --texture-size 64
flags=(--size 4 --supersample 1)
mkdir -p "$tmp/local"
"$vtbake" -q --threads 2 bake "$tmp/scene/scene.gltf" -o "$tmp/local/out.vtpf" "${flags[@]}"

# The victim: shard 2's first run is killed (SIGKILL) once its part is staged, mid-work.
cat >"$tmp/vtbake-kill-one" <<EOF
#!/usr/bin/env bash
if [[ " \$* " == *" --shard 2/4 "* && ! -e "$tmp/killed-once" ]]; then
  touch "$tmp/killed-once"
  "$vtbake" "\$@" &
  pid=\$!
  for i in \$(seq 5000); do
    compgen -G "$tmp/farm/work/parts/shard-2-of-4.part.tmp-*" >/dev/null && break
    kill -0 \$pid 2>/dev/null || break
    sleep 0.002
  done
  kill -KILL \$pid
  wait \$pid
  exit \$?
fi
exec "$vtbake" "\$@"
EOF
chmod +x "$tmp/vtbake-kill-one"

PATH="$(dirname "$vtbake"):$PATH" "$src/scripts/farm.sh" --work "$tmp/farm/work" --shards 4 \
  --cpus 1 --time 10:00 --retries 2 --poll 0.5 --vtbake "$tmp/vtbake-kill-one" \
  -- "$tmp/scene/scene.gltf" -o "$tmp/farm/out.vtpf" "${flags[@]}" | tee "$tmp/farm.log"

[[ -e "$tmp/killed-once" ]] || fail "shard 2 was never started"
grep -q "failed 1" "$tmp/farm.log" || fail "Slurm did not report the killed shard as failed"
grep -q "resubmitted shards 2 as job" "$tmp/farm.log" || fail "the farm did not resubmit shard 2 alone"
# The resubmitted shard completed the set, so it merged: no merge job was needed.
grep -q "(by the last shard)" "$tmp/farm.log" || fail "no shard merged (the farm fell back to a merge job)"
grep -q "merge job" "$tmp/farm.log" && fail "the farm submitted a merge job although a shard merged"
cmp "$tmp/local/out.vtpf" "$tmp/farm/out.vtpf" || fail "merged page file differs from the local bake"
cmp "$tmp/local/out.glb" "$tmp/farm/out.glb" || fail "merged unwrapped scene differs from the local bake"
# --merge-job: the merge as a job of its own after the array (the chain before --merge-last).
"$src/scripts/farm.sh" --work "$tmp/farm2/work" --shards 2 --cpus 1 --time 10:00 --poll 0.5 \
  --merge-job --vtbake "$vtbake" -- "$tmp/scene/scene.gltf" -o "$tmp/farm2/out.vtpf" \
  "${flags[@]}" | tee "$tmp/farm2.log"
grep -q ", merge job [0-9]" "$tmp/farm2.log" || fail "--merge-job submitted no merge job"
cmp "$tmp/local/out.vtpf" "$tmp/farm2/out.vtpf" || fail "--merge-job: merged page file differs"
echo "PASS: 4 shards through Slurm, one killed and resubmitted, merge byte-identical ($(stat -c %s "$tmp/farm/out.vtpf") bytes)"
