#!/usr/bin/env bash
# Every GPU figure of the Warp backend in one command (one sitting of a GPU machine; docs/backends.md
# says how to bring the packages to an offline one).
#   usage: benchmarks/gpu_suite.sh OUT_DIR [TRAIN_SECONDS] [NUM_ENVS] [TRAIN_OVERRIDES...]
# Writes into OUT_DIR:
#   gpu.txt           the GPU's name, memory and driver
#   pytest_gpu.txt    `pytest -m gpu`: every pair stepped and a short training under sync-debug "error"
#   bench_warp.jsonl  `roto bench` of all 8 (task, robot) pairs at NUM_ENVS (default 8192)
#   scaling.jsonl     Shadow Bounce at 1k, 4k, 8k, 16k and 32k envs
#   update_cost.jsonl one PPO update of blind Shadow Bounce at NUM_ENVS: eager, CUDA graph, fused
#                     Adam, TF32 and mixes of them (benchmarks/update_cost.py)
#   train_TASK_ROBOT/ if TRAIN_SECONDS > 0: blind TRAIN_TASK on TRAIN_ROBOT (default bounce, shadow) at NUM_ENVS, stopped after that many
#                     seconds (scalars.csv: perf/steps_per_s; evaluations.jsonl: the evaluation curve),
#                     with policy_best.pt / policy_latest.pt (weights and settings only, for `roto eval`
#                     and `roto play` elsewhere); TRAIN_OVERRIDES go to `roto train` (ppo.cuda_graph=true,
#                     --agent_cfg experiments/baoding_configs/baoding_cpu_shadow.yaml)
#   suite.log         one line per step: exit status and seconds
# A short lease runs a subset, chosen by environment variables (defaults: everything):
#   PAIRS="bounce:shadow"        the (task:robot) pairs benched (default all eight)
#   SCALING="8192"               the env counts of the scaling line (default 1024 ... 32768)
#   PYTEST_FILES="tests/rl/..."  the GPU test files (default: every gpu-marked test under tests/)
#   UPDATE_AGENTS="bounce bounce_cpu_quickstart"  agent configs whose update is timed (default bounce)
#   (each of these four set to "" skips its step)
#   DEADLINE=<epoch seconds>     training stops 60 s before it (room for the policies), whatever TRAIN_SECONDS says
#   TRAIN_TASK=baoding TRAIN_ROBOT=shadow  what the training trains (default bounce, shadow)
# Exits non-zero, naming the failed steps and the tail of their error output, if any step failed.
set -uo pipefail
out=${1:?usage: benchmarks/gpu_suite.sh OUT_DIR [TRAIN_SECONDS] [NUM_ENVS] [TRAIN_OVERRIDES...]}
train_s=${2:-0}
num_envs=${3:-8192}
train_overrides=("${@:4}")
export ROTO_WARP_CACHE=${ROTO_WARP_CACHE:-/tmp/roto-warp-cache}
mkdir -p "$out"
failed=()

step() {  # step NAME STDOUT_FILE COMMAND...: run it, log status and time, remember a failure
  local name=$1 stdout=$2 start status
  shift 2
  start=$(date +%s)
  "$@" >> "$stdout" 2>> "$out/$name.err"
  status=$?
  echo "$name: exit $status, $(( $(date +%s) - start )) s" | tee -a "$out/suite.log"
  if [ "$status" -ne 0 ]; then failed+=("$name"); fi
}

nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv > "$out/gpu.txt" 2>&1 || failed+=(nvidia-smi)
all_pairs="bounce:shadow bounce:shadow_lite bounce:allegro bounce:orca baoding:shadow baoding:shadow_lite baoding:allegro baoding:orca"
read -r -a pytest_files <<< "${PYTEST_FILES-tests}"
if [ ${#pytest_files[@]} -gt 0 ]; then
  step pytest_gpu "$out/pytest_gpu.txt" python3 -m pytest -q -m gpu -p no:cacheprovider "${pytest_files[@]}"
fi
for agent in ${UPDATE_AGENTS-bounce}; do
  step "update_cost_$agent" "$out/update_cost.jsonl" python3 benchmarks/update_cost.py --device cuda \
    --num_envs "$num_envs" --agent_cfg "$agent"
done
for pair in ${PAIRS-$all_pairs}; do
  task=${pair%%:*} robot=${pair#*:}
  step "bench_${task}_${robot}" "$out/bench_warp.jsonl" python3 -m roto.cli bench --backend warp --device cuda \
    --task "$task" --robot "$robot" --num_envs "$num_envs" --steps 200 --json
done
for n in ${SCALING-1024 4096 8192 16384 32768}; do
  step "scaling_$n" "$out/scaling.jsonl" python3 -m roto.cli bench --backend warp --device cuda \
    --task bounce --robot shadow --num_envs "$n" --steps 200 --json
done
if [ -n "${DEADLINE:-}" ]; then
  left=$(( DEADLINE - $(date +%s) - 60 ))
  if [ "$left" -lt "$train_s" ]; then train_s=$(( left > 0 ? left : 0 )); fi
fi
if [ "$train_s" -gt 0 ]; then
  train_task=${TRAIN_TASK:-bounce} train_robot=${TRAIN_ROBOT:-shadow}
  run="$out/train_${train_task}_${train_robot}"
  # SIGINT at the time limit ends the run like Ctrl-C (exit 124 from timeout is the expected end)
  timeout --signal=INT "$train_s" python3 -m roto.cli train --backend warp --device cuda --task "$train_task" \
    --robot "$train_robot" --obs blind --num_envs "$num_envs" --steps 200000000 --seed 0 --run_dir "$run" \
    --no_progress "${train_overrides[@]}" > "$out/train.log" 2>&1
  status=$?
  echo "train: exit $status after at most $train_s s" | tee -a "$out/suite.log"
  if [ "$status" -ne 0 ] && [ "$status" -ne 124 ]; then failed+=(train); fi
  for which in best latest; do
    step "policy_$which" /dev/null python3 -c "import sys, torch
from roto.rl.run_dir import POLICY_KEYS  # what a policy-only checkpoint holds (best.pt already is one)
state = torch.load(sys.argv[1], weights_only=True, map_location='cpu')
torch.save({k: state[k] for k in POLICY_KEYS}, sys.argv[2])" "$run/checkpoints/$which.pt" "$run/policy_$which.pt"
  done
  rm -f "$run"/checkpoints/*.pt  # full checkpoints hold the envs' state (hundreds of MB at 8192 envs)
fi
if [ ${#failed[@]} -gt 0 ]; then
  for name in "${failed[@]}"; do
    echo "FAILED: $name" >&2
    tail -5 "$out/$name.err" >&2 2>/dev/null
  done
  exit 1
fi
echo "gpu suite: every step passed ($(cat "$out/bench_warp.jsonl" 2>/dev/null | wc -l) bench lines)"
