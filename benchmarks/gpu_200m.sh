#!/usr/bin/env bash
# One prepared call of a GPU sitting: blind Shadow Bounce with bounce_gpu at 8192 envs to 200 M env
# steps (the run stops there by itself), then, for the time left, the Shadow's Baoding recipe with
# ORCA's round aids (baoding_cpu_shadow_round: a bank of round starts, only round swaps paid in
# training; together they made ORCA carry the balls round on the CPU), since at 8192 envs the plain
# recipe swings them (docs/results.md).
#   usage (on the GPU machine, in the repo root, after `bash benchmarks/gpu_machine.sh stage .whl1`,
#   `.whl2`, `.whl3` in three calls; .whl4 holds the last wheel part and the kernel cache archive
#   kernels*.tar.xz.part-NN of Shadow Bounce and Baoding, so nothing compiles):
#     BUDGET_S=580 bash benchmarks/gpu_200m.sh
# First the GPU test of the Baoding recipe's env (sync-free with every training aid, about 30 s);
# AIDS_TEST=0 skips it, leaving the 200 M run about 30 s more of the budget.
# Everything lands in $OUT: results.tgz.part-NN (`cat results.tgz.part-* | tar -xzf -` here), sitting.log.
set -u
t0=$(date +%s)
deadline=$(( t0 + ${BUDGET_S:?usage: BUDGET_S=seconds bash benchmarks/gpu_200m.sh} ))
out=/tmp/sitting
mkdir -p "$out"
log() { echo "$* ($(( $(date +%s) - t0 )) s)" | tee -a "$out/sitting.log"; }
bash benchmarks/gpu_machine.sh install .whl4 || exit 1
export PYTHONPATH=/tmp/site:$PWD ROTO_WARP_CACHE=/tmp/wc PYTHONUNBUFFERED=1
log "install done"
# the recipe's env under CUDA's sync-debug mode (its recorder waited for the GPU every step until 2026-11-27)
if [ "${AIDS_TEST:-1}" != 0 ]; then
  python3 -m pytest -q -m gpu -p no:cacheprovider tests/envs/test_sync_free_step.py -k training_aids \
    > "$out/pytest_gpu_aids.txt" 2>&1
  log "pytest (aids): exit $?"
fi
# 200 M env steps take about 420 s of training and 40 s of evaluations at 479 k env steps/s (H100)
DEADLINE=$(( deadline + 35 )) PAIRS=bounce:shadow SCALING="" PYTEST_FILES="" UPDATE_AGENTS="" \
  bash benchmarks/gpu_suite.sh "$out/bounce_200m" 600 8192 --agent_cfg bounce_gpu --seed 2
log "bounce done"
if [ $(( deadline - $(date +%s) )) -gt 150 ]; then
  DEADLINE=$(( deadline + 35 )) PAIRS="" SCALING="" PYTEST_FILES="" UPDATE_AGENTS="" TRAIN_TASK=baoding \
    TRAIN_ROBOT=shadow bash benchmarks/gpu_suite.sh "$out/baoding_round" 600 8192 \
    --agent_cfg experiments/baoding_configs/baoding_cpu_shadow_round.yaml ppo.cuda_graph=true ppo.tf32_update=true \
    run.eval_every=20 run.checkpoint_every=40
  log "baoding done"
fi
cp "$out/sitting.log" "$OUT/"
OUT=$OUT bash benchmarks/gpu_machine.sh pack "$out"
