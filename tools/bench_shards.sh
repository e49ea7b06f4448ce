#!/usr/bin/env bash
# Cost of sharding (BENCHMARKS.md, "Sharded rendering"): the CPU time of one
# single-threaded render against N single-threaded shards plus their merge,
# the size of a partial file per megapixel, and (when a Slurm cluster
# answers, e.g. after `tools/slurm-local.sh start`) the wall time of
# `submit slurm --shards 2` against one render with 2 threads.
#
#   tools/bench_shards.sh [SCENE] [SPP] [SHARDS]
#
# Run it on a quiet machine; it prints the load average beside the figures.
set -euo pipefail

scene=${1:-scenes/compare_cornell.toml}
spp=${2:-256}
shards=${3:-8}
bin=${AIRLIGHT:-target/release/airlight}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

cpu() { # user+system CPU seconds of a command
  /usr/bin/time -f '%U %S' -o "$work/t" "$@" >/dev/null 2>&1
  awk '{ printf "%.2f", $1 + $2 }' "$work/t"
}
wall() {
  local start end
  start=$(date +%s.%N)
  "$@" >/dev/null 2>&1
  end=$(date +%s.%N)
  echo "$end - $start" | bc -l | xargs printf '%.2f'
}

echo "scene $scene, $spp spp, $shards shards; load $(cut -d' ' -f1-3 /proc/loadavg)"
single=$(cpu "$bin" render "$scene" --spp "$spp" --threads 1 -q -o "$work/single.exr")
total=0
for ((k = 0; k < shards; k++)); do
  t=$(cpu "$bin" render "$scene" --spp "$spp" --threads 1 -q --shard "$k/$shards" -o "$work/part$k.exr")
  total=$(echo "$total + $t" | bc -l)
done
merge=$(cpu "$bin" merge "$work"/part*.exr -o "$work/merged.exr")
total=$(echo "$total + $merge" | bc -l)
"$bin" compare "$work/single.exr" "$work/merged.exr" | grep -i 'max' || true
cmp -s "$work/single.exr" "$work/merged.exr" && same="byte-identical" || same="DIFFERENT"
printf 'single render: %s s CPU\n%d shards + merge: %.2f s CPU (merge %s s), %+.1f%%; merged image %s\n' \
  "$single" "$shards" "$total" "$merge" "$(echo "($total / $single - 1) * 100" | bc -l)" "$same"
read -r width height < <("$bin" info "$scene" | sed -n 's/^image: \([0-9]*\)×\([0-9]*\),.*/\1 \2/p')
bytes=$(stat -c %s "$work/part0.exr")
printf 'partial file: %d bytes for %dx%d, %.2f MB per megapixel\n' "$bytes" "$width" "$height" \
  "$(echo "$bytes / ($width * $height)" | bc -l)"
echo "load $(cut -d' ' -f1-3 /proc/loadavg)"

if command -v sbatch >/dev/null && scontrol ping 2>/dev/null | grep -q UP; then
  two=$(wall "$bin" render "$scene" --spp "$spp" --threads 2 -q -o "$work/two.exr")
  slurm=$(wall "$bin" submit slurm "$scene" --shards 2 --wait -o "$work/slurm.exr" -- --spp "$spp")
  cmp -s "$work/single.exr" "$work/slurm.exr" && same="byte-identical" || same="DIFFERENT"
  echo "render --threads 2: $two s wall; submit slurm --shards 2 --wait: $slurm s wall; merged image $same"
  echo "load $(cut -d' ' -f1-3 /proc/loadavg)"
else
  echo "no Slurm cluster answers: skipped the submit comparison"
fi
