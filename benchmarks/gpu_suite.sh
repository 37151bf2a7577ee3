#!/usr/bin/env bash
# Every GPU figure of the Warp backend in one command (one call of a lent GPU machine; see
# docs/backends.md for how the packages get there).
#   usage: benchmarks/gpu_suite.sh OUT_DIR [TRAIN_SECONDS] [NUM_ENVS]
# Writes OUT_DIR/gpu.txt, OUT_DIR/bench_warp.jsonl (one line per (task, robot) pair) and, if
# TRAIN_SECONDS > 0, a blind Shadow Bounce training run OUT_DIR/train_bounce_shadow/ cut off after
# that many seconds (its scalars.csv holds perf/steps_per_s, its evaluations.jsonl the evaluation curve).
set -uo pipefail
out=${1:?usage: benchmarks/gpu_suite.sh OUT_DIR [TRAIN_SECONDS] [NUM_ENVS]}
train_s=${2:-0}
num_envs=${3:-8192}
export ROTO_WARP_CACHE=${ROTO_WARP_CACHE:-/tmp/roto-warp-cache}
mkdir -p "$out"
nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv > "$out/gpu.txt" 2>&1
for task in baoding bounce; do
  for robot in shadow shadow_lite allegro orca; do
    python3 -m roto.cli bench --backend warp --device cuda --task "$task" --robot "$robot" \
      --num_envs "$num_envs" --steps 200 --json >> "$out/bench_warp.jsonl" 2>> "$out/bench_warp.err"
  done
done
if [ "$train_s" -gt 0 ]; then
  timeout --signal=INT "$train_s" python3 -m roto.cli train --backend warp --device cuda --task bounce \
    --robot shadow --obs blind --num_envs "$num_envs" --steps 200000000 --seed 0 \
    --run_dir "$out/train_bounce_shadow" --no_progress > "$out/train.log" 2>&1
  rm -f "$out"/train_bounce_shadow/checkpoints/agent_*.pt  # keep latest/best only (transfer size)
fi
echo "done: $(wc -l < "$out/bench_warp.jsonl") bench lines"
