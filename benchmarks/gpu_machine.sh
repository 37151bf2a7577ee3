#!/usr/bin/env bash
# Steps of a sitting on a lent GPU machine that has no package index (docs/backends.md, "Running on
# an offline GPU machine"); run in roto's source tree there. Packages go to /tmp/site, MuJoCo Warp's
# kernel cache to /tmp/wc; afterwards every command needs
#   export PYTHONPATH=/tmp/site:$PWD ROTO_WARP_CACHE=/tmp/wc
#
#   bash benchmarks/gpu_machine.sh stage DIR    copy DIR's files, not its folders (one part of
#                                               benchmarks/gpu_wheels.sh, carried by one transfer) into /tmp/whl
#   bash benchmarks/gpu_machine.sh install [DIR]  stage DIR if given, then unpack Warp and install the
#                                               wheels staged so far into /tmp/site; unpack the kernel
#                                               caches staged so far (kernels*.tar.xz.part-NN, from `pack`,
#                                               or whole warp_cuda_*.tar.xz archives) into /tmp/wc
#   bash benchmarks/gpu_machine.sh pack DIR     DIR (results of the sitting) into $OUT/results.tgz.part-NN without
#                                               full checkpoints or TensorBoard events, and the kernel cache into
#                                               $OUT/kernels.tar.xz.part-NN, each part at most 15 MiB (what a call
#                                               brings back is limited to 16 MiB a file; two Baoding policies
#                                               with their critics already make 17 MB)
# Here, `cat results.tgz.part-* | tar -xzf -` unpacks the results.
# Here, the parts that came back go into a folder of their own that git ignores (like the wheel
# parts' .whl1 ...), which a later sitting carries and stages in one more call:
#   mkdir -p .whl_kernels && cp kernels.tar.xz.part-* .whl_kernels/
set -euo pipefail
whl=/tmp/whl site=/tmp/site cache_parent=/tmp

stage() {
  mkdir -p "$whl"
  find "${1:?usage: gpu_machine.sh stage DIR}" -maxdepth 1 -type f -exec cp -t "$whl" {} +
}

install() {
  if [ $# -gt 0 ]; then stage "$1"; fi
  mkdir -p "$site"
  cat "$whl"/warp.tar.xz.part-* | tar -xJf - -C "$site"
  python3 -m pip install -q --no-index --no-deps --target "$site" "$whl"/*.whl
  if compgen -G "$whl/kernels*.tar.xz.part-*" > /dev/null; then
    cat "$whl"/kernels*.tar.xz.part-* | tar -xJf - -C "$cache_parent"
  fi
  for archive in "$whl"/warp_cuda_*.tar.xz; do
    if [ -f "$archive" ]; then tar -xJf "$archive" -C "$cache_parent"; fi
  done
  echo "installed into $site; kernel cache $cache_parent/wc: $(du -sm "$cache_parent/wc" 2>/dev/null | cut -f1) MiB"
}

pack() {
  local dir=${1:?usage: gpu_machine.sh pack DIR}
  : "${OUT:?pack writes into \$OUT}"
  tar -C "$(dirname "$dir")" --exclude='*tfevents*' --exclude='checkpoints' -czf - "$(basename "$dir")" \
    | split -b 15M -d -a 2 - "$OUT/results.tgz.part-"
  if [ -d "$cache_parent/wc" ]; then
    tar -C "$cache_parent" -cf - wc | xz -T0 -6 | split -b 15M -d -a 2 - "$OUT/kernels.tar.xz.part-"
  fi
  ls -l "$OUT"
}

case "${1:-}" in
  stage | install | pack) "$@" ;;
  *) echo "usage: gpu_machine.sh stage DIR | install [DIR] | pack DIR (got '${1:-}')" >&2; exit 2 ;;
esac
