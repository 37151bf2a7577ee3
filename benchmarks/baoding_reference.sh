#!/usr/bin/env bash
# The Baoding reference controller on every hand: 16 episodes each (about 15 minutes a hand on
# 2 threads), its figures and the states just before each swap; then the same controller carrying
# the balls round (--turn_weight 3: a cost per turn the pair still has to go counter-clockwise),
# whose states make each hand's round bank (R_round_preswap). A hand whose JSON exists is skipped,
# so a cut-off run resumes where it stopped. The banks go where roto ships them (roto/banks/).
#     bash benchmarks/baoding_reference.sh [episodes]
set -euo pipefail
episodes=${1:-16}
out=benchmarks/results/baoding_reference
mkdir -p "$out"
run() {  # run NAME EXTRA_ARGS...: roto demo on robot $robot into $out/NAME.json and roto/banks/NAME_preswap.npz
    local name=$1
    shift
    if [[ -s "$out/$name.json" ]]; then
        echo "skip $name: $out/$name.json exists"
        return
    fi
    roto demo --task baoding --robot "$robot" --episodes "$episodes" --threads 2 --seed 0 \
        --preswap_out "roto/banks/${name}_preswap.npz" "$@" > "$out/$name.json.part"
    mv "$out/$name.json.part" "$out/$name.json"
}
for robot in shadow shadow_lite allegro orca; do
    run "$robot"
    run "${robot}_round" --turn_weight 3
done
