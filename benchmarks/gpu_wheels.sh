#!/usr/bin/env bash
# Pack roto's simulation packages for an offline GPU machine (x86-64 Linux, Python 3.12) into parts
# that fit a transfer limit: warp-lang (168 MB as a wheel) unpacked without its examples and
# compressed with xz (104 MB), the other wheels as they are, split into DIR/part1 .. DIR/partN of at
# most PART_MIB MiB each (default 48: a 64 MiB transfer that also carries the source tree, about 11 MiB
# and growing with the results it keeps).
#   usage: benchmarks/gpu_wheels.sh DIR [PART_MIB]
# On the GPU machine, with every part's files copied into one folder W:
#   cd W && cat warp.tar.xz.part-* | tar -xJf - -C SITE && pip install --no-index --no-deps --target SITE *.whl
# then run roto from its source tree with PYTHONPATH=SITE:$PWD (docs/backends.md).
set -euo pipefail
out=${1:?usage: benchmarks/gpu_wheels.sh DIR [PART_MIB]}
part_mib=${2:-48}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
download() {  # wheels for CPython 3.12 on x86-64 manylinux, without their dependencies
  python3 -m pip download -q --no-deps --only-binary=:all: --python-version 3.12 --implementation cp \
    --platform manylinux_2_28_x86_64 --platform manylinux_2_27_x86_64 --platform manylinux_2_17_x86_64 \
    --platform manylinux2014_x86_64 -d "$1" "${@:2}"
}
download "$tmp/warp" warp-lang==1.19.0
download "$tmp/wheels" mujoco==4.0.0 mujoco-core==4.0.0 mujoco-studio==4.0.0 mujoco-warp==4.0.0 gymnasium==1.4.0 \
  farama-notifications gymnasium-robotics==1.4.2 orca-sim==0.1.0 tensorboardX==2.6.5 etils \
  optuna==5.0.0 colorlog sqlalchemy alembic mako tqdm  # roto.sweep: without them seven test modules do not collect
mkdir -p "$tmp/unpacked" "$tmp/files"
python3 -m zipfile -e "$tmp"/warp/*.whl "$tmp/unpacked"
rm -rf "$tmp/unpacked/warp/examples"
tar -C "$tmp/unpacked" -cf - . | xz -T0 -6 | split -b "${part_mib}M" -d -a 2 - "$tmp/files/warp.tar.xz.part-"
mv "$tmp"/wheels/*.whl "$tmp/files/"
# first fit, largest first, into parts of at most part_mib MiB
cap=$((part_mib * 1024 * 1024))
rm -rf "$out" && mkdir -p "$out"
declare -a used=()
for f in $(ls -S "$tmp"/files/*); do
  size=$(stat -c %s "$f")
  k=0
  while [ "$k" -lt "${#used[@]}" ] && [ $(( used[k] + size )) -gt "$cap" ]; do k=$((k + 1)); done
  if [ "$k" -eq "${#used[@]}" ]; then used+=(0); mkdir -p "$out/part$((k + 1))"; fi
  mv "$f" "$out/part$((k + 1))/"
  used[k]=$(( used[k] + size ))
done
for d in "$out"/part*; do echo "$d $(du -sm "$d" | cut -f1) MiB: $(ls "$d" | tr '\n' ' ')"; done
