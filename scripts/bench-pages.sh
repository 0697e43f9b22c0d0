#!/usr/bin/env bash
# Re-measure the figures of the benchmark pages: each bench below runs through
# tests/bench/record.py, which writes what it printed to docs/benchmarks/<bench>.md with the date,
# the machine and the command (docs/benchmarks.md includes those pages).
#   bash scripts/bench-pages.sh                    # every page (the benches that start servers load both cores for minutes)
#   bash scripts/bench-pages.sh bench_solver ...   # only these
# A bench measures the machine it runs on: run it on a quiet one and commit the pages with the change
# they measure. The options are the benches' own (their module docstrings).
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/venv.sh
ensure_venv test

declare -A options=(
  [bench_solver]=""
  [bench_controller]=""
  [bench_gradebook]=""
  [bench_startup]=""
  [bench_trainee]=""
  [bench_panel]=""
  [bench_scene_step]=""
  [bench_server]=""
  [bench_jobs]=""
  [bench_class_load]="--counts 1,30,60,100 --duration 20"
)
order=(bench_solver bench_controller bench_gradebook bench_startup bench_trainee bench_panel bench_scene_step
       bench_server bench_jobs bench_class_load)
if [ $# -gt 0 ]; then order=("$@"); fi
for bench in "${order[@]}"; do
  if [ -z "${options[$bench]+set}" ]; then echo "bench-pages.sh: no bench $bench (one of: ${!options[*]})" >&2; exit 2; fi
  echo "== $bench ${options[$bench]}" >&2
  # shellcheck disable=SC2086  # the options are words
  .venv/bin/python tests/bench/record.py "$bench" ${options[$bench]}
done
