#!/usr/bin/env bash
# Ping/pong latency (half round trip) of the DDS stacks against the floor under them: the same round trip over
# bare UDP sockets (`udp-floor`, examples/src/bin/udp-floor.rs), in interleaved rounds inside one private network
# namespace (loopback). What each stack adds to the kernel's part is its figure less the floor's. A benchmark to
# read, not a timed test.
#
#   scripts/bench-latency.sh                                   # floor, ours, Cyclone 11; 16 B, 1 KiB, 64 KiB
#   BENCH_SECONDS=10 BENCH_ROUNDS=5 LAT_SIZES="16" scripts/bench-latency.sh
#   STACKS="floor floorc floorm ours cy11" scripts/bench-latency.sh  # the floor with a connected socket / recvmmsg
#   BASE=/tmp/dds-perf-old STACKS="floor ours base cy11" scripts/bench-latency.sh
#
# Stacks: floor (`udp-floor`: blocking recv, sendto), floorc (`udp-floor connected`: connect + send), floorm
# (`udp-floor mmsg`: recvmmsg 8 deep, as our receive threads), ours (`dds-perf`, OURS=), base (BASE=), cy11
# (Cyclone 11.0.1's ddsperf, CYCLONE11=), cy010 (Debian's ddsperf 0.10.2). Each measurement is `X pong` <-
# `X ping size S`; the figure is the median over the ping's per-second "50%" and "99%" columns after the first
# second; the table gives the median over the rounds. Ratios are against the last stack (cy11 by default).
set -euo pipefail
cd "$(dirname "$0")/.."
if [[ "${DDS_IN_NETNS:-}" != 1 ]]; then
  exec scripts/isolated "$0" "$@"
fi

secs=${BENCH_SECONDS:-5}
rounds=${BENCH_ROUNDS:-3}
lat_sizes=${LAT_SIZES:-16 1k 64k}
stacks=${STACKS:-floor ours cy11}
cy11_root=${CYCLONE11:-../shared/cyclonedds-11.0.1}
ours=${OURS:-target/release/dds-perf}
floor=${FLOOR:-target/release/udp-floor}
[[ -x $ours ]] || cargo build --release -p dds-examples --bin dds-perf
[[ -x $floor ]] || cargo build --release -p dds-examples --bin udp-floor
out=$(mktemp -d)
trap 'kill $(jobs -p) 2>/dev/null || true; rm -rf "$out"' EXIT

source scripts/cyclone11.sh
source scripts/bench-lib.sh

declare -A cmd=([ours]=$ours [cy010]=/usr/bin/ddsperf [floor]=$floor [floorc]="$floor connected"
  [floorm]="$floor mmsg")
[[ -n ${BASE:-} ]] && cmd[base]=$BASE
if [[ -x $cy11_root/bin/ddsperf ]]; then
  cmd[cy11]=$(cyclone11_ddsperf "$cy11_root" "$out")
fi
read -r -a stacks <<<"$stacks"
for s in "${stacks[@]}"; do
  [[ -n ${cmd[$s]:-} && -x ${cmd[$s]%% *} ]] || { echo "bench-latency: no program for stack $s" >&2; exit 2; }
done
ref=${stacks[-1]}
domain=${BENCH_DOMAIN:-100}

echo "bench-latency: $rounds rounds, ${secs}s per measurement, stacks ${stacks[*]}, loopback in a private netns," \
  "$(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg)"
for r in $(seq 1 "$rounds"); do
  for size in $lat_sizes; do
    for s in "${stacks[@]}"; do
      domain=$(((domain + 1) % 200)); echo "$size $s $(bench_latency "${cmd[$s]}" "$size" "$domain")" >>"$out/lat"
    done
  done
  echo "round $r done (load $(cut -d' ' -f1 /proc/loadavg))"
done

printf '\nlatency, half round trip, medians over %d rounds (p50 | p99 us)\n' "$rounds"
printf '%-6s' size
for s in "${stacks[@]}"; do printf ' %16s' "$s"; done
for s in "${stacks[@]:0:${#stacks[@]}-1}"; do printf ' %18s' "$s/$ref p50|p99"; done
[[ ${cmd[floor]} && " ${stacks[*]} " == *" floor "* ]] && for s in "${stacks[@]}"; do
  [[ $s == floor* ]] || printf ' %16s' "$s-floor p50"
done
echo
for size in $lat_sizes; do
  printf '%-6s' "$size"
  for s in "${stacks[@]}"; do printf ' %16s' "$(bench_median "$out/lat" "$size" "$s" 3) | $(bench_median "$out/lat" "$size" "$s" 4)"; done
  r50=$(bench_median "$out/lat" "$size" "$ref" 3)
  r99=$(bench_median "$out/lat" "$size" "$ref" 4)
  for s in "${stacks[@]:0:${#stacks[@]}-1}"; do
    printf ' %18s' "$(bench_ratio "$(bench_median "$out/lat" "$size" "$s" 3)" "$r50")|$(bench_ratio "$(bench_median "$out/lat" "$size" "$s" 4)" "$r99")"
  done
  if [[ " ${stacks[*]} " == *" floor "* ]]; then
    f50=$(bench_median "$out/lat" "$size" floor 3)
    for s in "${stacks[@]}"; do
      [[ $s == floor* ]] || printf ' %16s' "$(awk -v a="$(bench_median "$out/lat" "$size" "$s" 3)" -v b="$f50" 'BEGIN { printf "%+.1f", a - b }')"
    done
  fi
  echo
done
# Every round's figures, for the record.
printf '\nper round (size stack p50 p99):\n'
cat "$out/lat"
