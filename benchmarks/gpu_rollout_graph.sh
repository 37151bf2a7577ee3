#!/usr/bin/env bash
# One GPU sitting for the rollout's CUDA graph (ppo.cuda_graph_rollout) and blind Shadow Baoding at
# 8192 envs: the graphed rollout's GPU tests; simulation alone (a `roto bench` of bounce:shadow);
# `bounce_gpu` trained for SPEED_S seconds without and then with the graphed rollout (compare
# perf/inference_s, perf/simulation_s and perf/steps_per_s in their scalars.csv); then the Shadow's
# Baoding recipe (baoding_cpu, every hand's; graphed update, and the graphed rollout if its tests passed)
# for the time left, seed 0.
#   usage (on the GPU machine, in the repo root, after `bash benchmarks/gpu_machine.sh install ...`
#   and `export PYTHONPATH=/tmp/site:$PWD ROTO_WARP_CACHE=/tmp/wc`):
#     BUDGET_S=540 SPEED_S=60 bash benchmarks/gpu_rollout_graph.sh OUT_DIR
# OUT_DIR/tests.txt, OUT_DIR/bench/ (bench_warp.jsonl), OUT_DIR/eager/ and OUT_DIR/graphed/ (the two
# Bounce trainings), OUT_DIR/baoding/ (train_baoding_shadow/: scalars.csv, evaluations.jsonl, policies).
set -u
t0=$(date +%s)
out=${1:?usage: BUDGET_S=540 SPEED_S=60 bash benchmarks/gpu_rollout_graph.sh OUT_DIR}
deadline=$(( t0 + ${BUDGET_S:-540} )) speed_s=${SPEED_S:-60}
mkdir -p "$out"
export PYTHONUNBUFFERED=1 SCALING="" PYTEST_FILES="" UPDATE_AGENTS=""
python3 -m pytest -q -m gpu -p no:cacheprovider tests/rl/test_graphed_step.py > "$out/tests.txt" 2>&1
tests=$?
rollout=ppo.cuda_graph_rollout=true
if [ "$tests" -ne 0 ]; then rollout=ppo.cuda_graph_rollout=false; fi
echo "graphed rollout tests: exit $tests; Baoding trains with $rollout" | tee "$out/sitting.log"
PAIRS=bounce:shadow bash benchmarks/gpu_suite.sh "$out/bench" 0 8192
PAIRS="" bash benchmarks/gpu_suite.sh "$out/eager" "$speed_s" 8192 --agent_cfg bounce_gpu ppo.cuda_graph_rollout=false
if [ "$tests" -eq 0 ]; then
  PAIRS="" bash benchmarks/gpu_suite.sh "$out/graphed" "$speed_s" 8192 --agent_cfg bounce_gpu ppo.cuda_graph_rollout=true
fi
DEADLINE=$deadline PAIRS="" TRAIN_TASK=baoding TRAIN_ROBOT=shadow bash benchmarks/gpu_suite.sh "$out/baoding" 600 8192 \
  --agent_cfg baoding_cpu ppo.cuda_graph=true "$rollout" run.eval_every=10 run.checkpoint_every=20
echo "sitting: $(( $(date +%s) - t0 )) s" | tee -a "$out/sitting.log"
