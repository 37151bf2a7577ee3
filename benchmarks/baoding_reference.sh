#!/usr/bin/env bash
# The Baoding reference controller on every hand: 16 episodes each (about 15 minutes a hand on
# 2 threads), its figures and the states just before each swap. A hand whose JSON exists is skipped,
# so a cut-off run resumes where it stopped. The banks go where roto ships them (roto/banks/).
#     bash benchmarks/baoding_reference.sh [episodes]
set -euo pipefail
episodes=${1:-16}
out=benchmarks/results/baoding_reference
mkdir -p "$out"
for robot in shadow shadow_lite allegro orca; do
    if [[ -s "$out/$robot.json" ]]; then
        echo "skip $robot: $out/$robot.json exists"
        continue
    fi
    roto demo --task baoding --robot "$robot" --episodes "$episodes" --threads 2 --seed 0 \
        --preswap_out "roto/banks/${robot}_preswap.npz" > "$out/$robot.json.part"
    mv "$out/$robot.json.part" "$out/$robot.json"
done
