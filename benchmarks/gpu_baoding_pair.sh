#!/usr/bin/env bash
# Blind Shadow Baoding at 8192 envs on one GPU sitting: the CPU recipe (baoding_cpu_shadow: a critic
# that reads the task's state, 4 epochs, and three training-only aids: half the training starts replayed
# from the Shadow's bank of pre-swap states, its own swaps recorded into it, a latch radius narrowing
# from 2.5 to 1 cm) against roto's own recipe (baoding), both with the CUDA-graph update,
# seed 0, each for half the time left after the Baoding kernels are compiled (by a `roto bench` of
# baoding:shadow, which also gives the simulation-only speed to compare with).
#   usage (on the GPU machine, in the repo root, after `bash benchmarks/gpu_machine.sh install ...`
#   and `export PYTHONPATH=/tmp/site:$PWD ROTO_WARP_CACHE=/tmp/wc`):
#     BUDGET_S=540 bash benchmarks/gpu_baoding_pair.sh OUT_DIR
# OUT_DIR/bench/ holds the bench line, OUT_DIR/recipe/ and OUT_DIR/roto/ each a benchmarks/gpu_suite.sh
# training (train_baoding_shadow/: scalars.csv, evaluations.jsonl, policy_best.pt, policy_latest.pt).
set -u
t0=$(date +%s)
out=${1:?usage: BUDGET_S=540 bash benchmarks/gpu_baoding_pair.sh OUT_DIR}
deadline=$(( t0 + ${BUDGET_S:-540} ))
export PYTHONUNBUFFERED=1 TRAIN_TASK=baoding TRAIN_ROBOT=shadow SCALING="" PYTEST_FILES="" UPDATE_AGENTS=""
PAIRS=baoding:shadow bash benchmarks/gpu_suite.sh "$out/bench" 0 8192
half=$(( (deadline - $(date +%s)) / 2 ))
every=(run.eval_every=10 run.checkpoint_every=20)
DEADLINE=$(( $(date +%s) + half )) PAIRS="" bash benchmarks/gpu_suite.sh "$out/recipe" 600 8192 \
  --agent_cfg experiments/baoding_configs/baoding_cpu_shadow.yaml ppo.cuda_graph=true "${every[@]}"
DEADLINE=$deadline PAIRS="" bash benchmarks/gpu_suite.sh "$out/roto" 600 8192 \
  --agent_cfg baoding ppo.cuda_graph=true "${every[@]}"
echo "baoding pair: $(( $(date +%s) - t0 )) s"
