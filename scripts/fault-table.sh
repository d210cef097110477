#!/usr/bin/env bash
# The fault table of docs/RELIABILITY.md: builds every case itself (page files, scenes, images,
# a bake to kill, a small tmpfs to fill) and runs vtbake on each; prints a Markdown table (one
# row per class: cases, crashes, hangs, silent wrong outputs, clear and unclear errors, accepted)
# and notes on anything that was not a clear error. Not run by CI: a few minutes of work.
#   scripts/fault-table.sh [--vtbake build/release/cli/vtbake] [--work DIR] [--seed N]
#                          [--cases N] [--only pages,scenes,images,kills,disk,truncation]
set -euo pipefail
cd "$(dirname "$0")/.."
exec python3 scripts/fault_table.py "$@"
