#!/usr/bin/env bash
# The GPU sitting of 2026-11-26, its last call: install the packages, then blind Shadow Bounce at
# 8192 envs with the CPU-tuned coefficients (bounce_cpu_quickstart) and the CUDA-graph update, as
# long as the lease allows. The two calls before it copied .whl1/* and .whl2/* into /tmp/whl:
# .whl1 ... .whl3 are the git-ignored parts that benchmarks/gpu_wheels.sh writes, .whl3 also holding
# the kernel-cache archive warp_cuda_h100_bounce_shadow.tar.xz (benchmarks/gpu_machine.sh now does
# these steps for any sitting).
#   usage (on the GPU machine, in the repo root): BUDGET_S=560 bash benchmarks/results/gpu_h200_2026-11-26/sitting.sh
# Everything lands in $OUT/sitting.tgz (the suite's files, the run without its full checkpoints).
set -u
t0=$(date +%s)
out=/tmp/sitting
mkdir -p /tmp/whl /tmp/site "$out"
cp .whl3/*.whl /tmp/whl/ && tar -xJf .whl3/warp_cuda_h100_bounce_shadow.tar.xz -C /tmp || exit 1
(cd /tmp/whl && cat warp.tar.xz.part-* | tar -xJf - -C /tmp/site \
  && python3 -m pip install -q --no-index --no-deps --target /tmp/site ./*.whl) || exit 1
export PYTHONPATH=/tmp/site:$PWD ROTO_WARP_CACHE=/tmp/wc PYTHONUNBUFFERED=1
echo "install: $(( $(date +%s) - t0 )) s"
deadline=$(( t0 + ${BUDGET_S:-560} ))
DEADLINE=$deadline PAIRS=bounce:shadow SCALING="" PYTEST_FILES="" UPDATE_AGENTS="" \
  bash benchmarks/gpu_suite.sh "$out/quickstart" 600 8192 --agent_cfg bounce_cpu_quickstart \
  ppo.cuda_graph=true run.eval_every=100 run.checkpoint_every=200
# if that training failed early, roto's own coefficients (the run of 2026-11-25) for the time left
if ! grep -qE "^train: exit (0|124) " "$out/quickstart/suite.log" && [ $(( deadline - $(date +%s) )) -gt 150 ]; then
  DEADLINE=$deadline PAIRS="" SCALING="" PYTEST_FILES="" UPDATE_AGENTS="" \
    bash benchmarks/gpu_suite.sh "$out/roto_coefficients" 600 8192 ppo.cuda_graph=true run.eval_every=100 \
    run.checkpoint_every=200
fi
echo "sitting: $(( $(date +%s) - t0 )) s"
tar -C /tmp --exclude='*tfevents*' --exclude='checkpoints' -czf "$OUT/sitting.tgz" sitting && ls -l "$OUT"
