#!/usr/bin/env bash
# Bakes one scene on a Slurm cluster (docs/FARM.md): a plan job, then a job array of shards
# chained with --dependency=afterok; the last shard to finish merges (`--merge-last`), so the
# chain has one dependency step. Waits, reporting progress from Slurm (squeue for live jobs;
# sacct when the cluster has accounting, else scontrol's records of finished jobs), and
# resubmits only the shards whose part is missing (`vtbake merge DIR --missing N`) until every
# shard is there and merged. A merge job runs only when no shard could merge (or --merge-job).
#
#   scripts/farm.sh --work DIR [--shards N] [--partition P] [--cpus C] [--plan-cpus C] [--mem M]
#                   [--time T] [--retries R] [--vtbake PATH] [--poll SECONDS] [--merge-job]
#                   -- SCENE -o OUT.vtpf [FLAGS]
# --cpus: CPUs per shard and merge job (default 2); --plan-cpus: for the plan job (default --cpus).
# --merge-job: merge in a job of its own after the array (a third chained step) instead.
#
# Everything after `--` is a `vtbake bake` command line; every job gets the same one. DIR and
# OUT must be on storage every node sees. Exit 0 when OUT is merged; 1 when shards still fail
# after the retries or the plan or merge job fails (the job logs are in DIR/logs).
set -euo pipefail

work="" shards=4 partition="" cpus=2 plan_cpus="" mem="" time_limit="1:00:00" retries=2 poll=1
merge_step=0
vtbake="${VTBAKE:-vtbake}"
usage() { sed -n '2,19p' "$0" | sed 's/^# \{0,1\}//'; exit 2; }
while [[ $# -gt 0 ]]; do
  case "$1" in
    --work) work="$2"; shift 2 ;;
    --shards) shards="$2"; shift 2 ;;
    --partition) partition="$2"; shift 2 ;;
    --cpus) cpus="$2"; shift 2 ;;
    --plan-cpus) plan_cpus="$2"; shift 2 ;;
    --mem) mem="$2"; shift 2 ;;
    --time) time_limit="$2"; shift 2 ;;
    --retries) retries="$2"; shift 2 ;;
    --vtbake) vtbake="$2"; shift 2 ;;
    --poll) poll="$2"; shift 2 ;;
    --merge-job) merge_step=1; shift ;;
    --) shift; break ;;
    -h|--help) usage ;;
    *) echo "farm.sh: unknown option $1" >&2; usage ;;
  esac
done
[[ -n "$work" && $# -gt 0 ]] || usage
[[ "$shards" =~ ^[1-9][0-9]*$ ]] || { echo "farm.sh: --shards $shards: expected N >= 1" >&2; exit 2; }
for tool in sbatch squeue scontrol scancel; do
  command -v "$tool" >/dev/null || { echo "farm.sh: $tool not found (Slurm client tools)" >&2; exit 2; }
done
bake_args=("$@")
# The output (-o/--output) for the merge.
output=""
for ((i = 0; i < ${#bake_args[@]}; ++i)); do
  case "${bake_args[i]}" in
    -o|--output) output="${bake_args[i+1]:-}" ;;
    --output=*) output="${bake_args[i]#--output=}" ;;
  esac
done
[[ -n "$output" ]] || { echo "farm.sh: the bake command needs -o OUT.vtpf" >&2; exit 2; }
mkdir -p "$work/logs" "$(dirname "$output")"
work=$(cd "$work" && pwd)

[[ -n "$plan_cpus" ]] || plan_cpus="$cpus"
sb=(sbatch --parsable --cpus-per-task="$cpus" --time="$time_limit" --chdir="$PWD")
[[ -n "$partition" ]] && sb+=(--partition="$partition")
[[ -n "$mem" ]] && sb+=(--mem="$mem")
quote() { printf '%q ' "$@"; }
bake_cmd=$(quote "$vtbake" --threads "$cpus" -q bake "${bake_args[@]}" --work "$work")

# Job state of one job or array task: sacct when there is accounting, else scontrol, else squeue.
have_sacct=0
if scontrol show config 2>/dev/null | grep -q '^AccountingStorageType *= *accounting_storage/slurmdbd'; then
  have_sacct=1
fi
job_states() {  # prints "ID STATE" for the job (every task of an array)
  if [[ $have_sacct -eq 1 ]]; then
    sacct -n -X -P -j "$1" -o JobID,State 2>/dev/null | tr '|' ' ' | awk '{print $1, $2}'
  else
    scontrol -o show job "$1" 2>/dev/null |
      sed -n 's/.*JobId=\([0-9]*\).*ArrayTaskId=\([0-9]*\).*JobState=\([A-Z_]*\).*/\2 \3/p;
              t; s/.*JobId=\([0-9]*\).*JobState=\([A-Z_]*\).*/\1 \2/p'
  fi
}
finished() {  # true when no task of job $1 is pending or running
  ! job_states "$1" | grep -qE ' (PENDING|RUNNING|CONFIGURING|COMPLETING|REQUEUED|SUSPENDED)'
}
state_of() { job_states "$1" | awk 'NR == 1 {print $2}'; }

plan_cmd=$(quote "$vtbake" --threads "$plan_cpus" -q bake "${bake_args[@]}" --work "$work" --plan "$work/plan.json")
plan_job=$("${sb[@]}" --cpus-per-task="$plan_cpus" -J vtbake-plan -o "$work/logs/plan.out" --wrap "$plan_cmd")
echo "farm: plan job $plan_job"
merge_last=""
[[ $merge_step -eq 0 ]] && merge_last=" --merge-last"
submit_shards() {  # $1 = array spec, $2 = dependency or ""
  local dep=()
  [[ -n "$2" ]] && dep=(--dependency="afterok:$2")
  "${sb[@]}" "${dep[@]}" -J vtbake-shard --array="$1" -o "$work/logs/shard-%a-%j.out" \
    --wrap "$bake_cmd --shard \$SLURM_ARRAY_TASK_ID/$shards$merge_last"
}
submit_merge() {  # $1 = dependency or ""
  local dep=()
  [[ -n "$1" ]] && dep=(--dependency="afterok:$1")
  "${sb[@]}" "${dep[@]}" -J vtbake-merge -o "$work/logs/merge-%j.out" \
    --wrap "$(quote "$vtbake" -q merge "$work" -o "$output")"
}
array_job=$(submit_shards "0-$((shards - 1))" "$plan_job")
merge_job=""
if [[ $merge_step -eq 1 ]]; then
  merge_job=$(submit_merge "$array_job")
  echo "farm: shard array $array_job (0-$((shards - 1))), merge job $merge_job"
else
  echo "farm: shard array $array_job (0-$((shards - 1))), the last shard merges"
fi
# True when a shard recorded the merge of this plan (DIR/merged.json, written by --merge-last).
plan_hash_of() { sed -n 's/^ *"plan_hash": *"\([0-9a-f]*\)".*/\1/p' "$1" 2>/dev/null | head -1; }
merged() {
  local h
  h=$(plan_hash_of "$work/merged.json")
  [[ -n "$h" && "$h" == "$(plan_hash_of "$work/plan.json")" ]]
}

wait_plan() {
  while ! finished "$plan_job"; do sleep "$poll"; done
  local s
  s=$(state_of "$plan_job")
  if [[ "$s" != COMPLETED ]]; then
    echo "farm: plan job $plan_job $s (log: $work/logs/plan.out)" >&2
    scancel "$array_job" $merge_job 2>/dev/null || true
    exit 1
  fi
}
wait_plan
attempt=0
last=""
while :; do
  # Progress of the shards from Slurm's records.
  while :; do
    # Asked before the states, so that the last line printed holds every shard's final state
    # (a shard that ended between the two queries was reported running, and its failure never).
    done_now=0
    finished "$array_job" && done_now=1
    line=$(job_states "$array_job" | awk '{n[$2]++} END {printf "done %d, failed %d, running %d, pending %d",
      n["COMPLETED"], n["FAILED"] + n["CANCELLED"] + n["TIMEOUT"] + n["NODE_FAIL"] + n["OUT_OF_MEMORY"],
      n["RUNNING"] + n["COMPLETING"], n["PENDING"]}')
    [[ "$line" != "$last" ]] && echo "farm: shards (job $array_job): $line"
    last="$line"
    [[ $done_now -eq 1 ]] && break
    sleep "$poll"
  done
  # The common end: the last shard merged (no vtbake start-up to ask).
  if [[ $merge_step -eq 0 ]] && merged; then
    echo "farm: merged $output (by the last shard)"
    exit 0
  fi
  missing=$("$vtbake" merge "$work" --missing "$shards" | paste -sd, -)
  [[ -z "$missing" ]] && break
  [[ -n "$merge_job" ]] && { scancel "$merge_job" 2>/dev/null || true; }
  if [[ $attempt -ge $retries ]]; then
    echo "farm: shards $missing still missing after $retries resubmissions (logs: $work/logs)" >&2
    exit 1
  fi
  attempt=$((attempt + 1))
  array_job=$(submit_shards "$missing" "")
  if [[ $merge_step -eq 1 ]]; then
    merge_job=$(submit_merge "$array_job")
    echo "farm: resubmitted shards $missing as job $array_job (attempt $attempt), merge job $merge_job"
  else
    echo "farm: resubmitted shards $missing as job $array_job (attempt $attempt)"
  fi
  last=""
done
# Every part is there but no shard merged (its merge failed, or --merge-job): a merge job.
if [[ -z "$merge_job" ]]; then
  merge_job=$(submit_merge "")
  echo "farm: every part is there but no shard merged; merge job $merge_job"
fi
while ! finished "$merge_job"; do sleep "$poll"; done
s=$(state_of "$merge_job")
if [[ "$s" != COMPLETED ]]; then
  echo "farm: merge job $merge_job $s (log: $work/logs/merge-$merge_job.out)" >&2
  exit 1
fi
echo "farm: merged $output"
