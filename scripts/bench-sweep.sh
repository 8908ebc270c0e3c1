#!/usr/bin/env bash
# Throughput over the whole sample-size envelope and ping/pong latency at three sizes: dds-perf (our stack)
# against Cyclone 11.0.1's ddsperf (../shared/cyclonedds-11.0.1) and Debian's Cyclone 0.10.2 ddsperf, in
# interleaved rounds, inside one private network namespace (loopback). A benchmark to read, not a timed test.
#
#   scripts/bench-sweep.sh                                  # 3 rounds, 6 s per measurement, every size
#   BENCH_SECONDS=10 BENCH_ROUNDS=5 scripts/bench-sweep.sh
#   SIZES="16 1k 64k" LAT_SIZES="16" scripts/bench-sweep.sh # a subset
#   STACKS="ours cy11" scripts/bench-sweep.sh               # leave a stack out
#   BASE=/tmp/dds-perf-old STACKS="ours base cy11" scripts/bench-sweep.sh  # an older build of ours as "base"
#
# Throughput: reliable keep-all, two processes, `X sub` <- `X pub size S`; the figure is the mean of the
#   subscriber's per-second "rate ... kS/s" lines after a 2 s warm-up. CPU: user+system seconds of both
#   processes (GNU time) per million samples received.
# Latency: `X pong` <- `X ping size S`; medians over the per-second lines of the "50%" and "99%" columns
#   (half round trip, us).
# Each round measures every stack back to back at one size before moving on, so that the drifts of a shared
# machine hit all of them; the tables give the median over the rounds of each figure and of each ratio.
set -euo pipefail
cd "$(dirname "$0")/.."
if [[ "${DDS_IN_NETNS:-}" != 1 ]]; then
  exec scripts/isolated "$0" "$@"
fi

secs=${BENCH_SECONDS:-6}
rounds=${BENCH_ROUNDS:-3}
sizes=${SIZES:-16 64 256 1k 2k 4k 8k 16k 64k 256k 1M 4M}
lat_sizes=${LAT_SIZES:-16 1k 64k}
stacks=${STACKS:-ours cy11 cy010}
cy11_root=${CYCLONE11:-../shared/cyclonedds-11.0.1}
ours=${OURS:-target/release/dds-perf}
[[ -x $ours ]] || cargo build --release -p dds-examples --bin dds-perf
out=$(mktemp -d)
trap 'kill $(jobs -p) 2>/dev/null || true; rm -rf "$out"' EXIT

source scripts/cyclone11.sh
source scripts/bench-lib.sh

# Both Cyclones get the socket buffers ours asks for (DDS_SOCKET_BUFFER_SIZE, 4 MB; the kernel doubles it). With
# their defaults they starve at 1 MiB and above (4 MiB, Cyclone 11: 0.01 kS/s against 0.22 with these), which
# is no comparison. Set CYCLONEDDS_URI to compare against something else.
export CYCLONEDDS_URI=${CYCLONEDDS_URI:-'<CycloneDDS><Domain><Internal><SocketReceiveBufferSize min="4MB"/><SocketSendBufferSize min="4MB"/></Internal></Domain></CycloneDDS>'}

declare -A cmd=([ours]=$ours [cy010]=/usr/bin/ddsperf)
# BASE=path: another build of dds-perf as stack "base" (before/after comparisons in one interleaved run).
[[ -n ${BASE:-} ]] && cmd[base]=$BASE
if [[ -x $cy11_root/bin/ddsperf ]]; then
  cmd[cy11]=$(cyclone11_ddsperf "$cy11_root" "$out")
fi
read -r -a stacks <<<"$stacks"
for s in "${stacks[@]}"; do
  [[ -n ${cmd[$s]:-} && -x ${cmd[$s]} ]] || { echo "bench-sweep: no program for stack $s" >&2; exit 2; }
done
domain=100

# throughput STACK SIZE DOMAIN -> "kS/s Mb/s CPU-seconds-per-million-samples" (0 0 0 when nothing arrived)
throughput() {
  local prog=${cmd[$1]} size=$2 dom=$3
  /usr/bin/time -f '%U %S' -o "$out/tsub" "$prog" -i "$dom" -D $((secs + 1)) sub >"$out/sub" 2>&1 &
  local sub=$!
  sleep 0.5
  /usr/bin/time -f '%U %S' -o "$out/tpub" "$prog" -i "$dom" -D "$secs" pub size "$size" >"$out/pub" 2>&1 || true
  wait "$sub" || true
  local cpu
  cpu=$(cat "$out/tsub" "$out/tpub" | awk '/^[0-9.]+ [0-9.]+$/ { s += $1 + $2 } END { print s + 0 }')
  awk -v cpu="$cpu" '/ size .* total .* rate / { n++; for (i = 1; i <= NF; i++) if ($i == "total") tot = $(i+1);
         if (n > 2) { for (i = 1; i <= NF; i++) if ($i == "rate") { s += $(i+1); m += $(i+3); c++ } } }
       END { if (c && tot > 0) printf "%.2f %.1f %.2f\n", s / c, m / c, cpu / tot * 1e6; else print "0 0 0" }' "$out/sub"
  if grep -q -E 'error|lost [1-9]' "$out/sub"; then
    echo "note: $1 size $size: subscriber reported errors or loss: $(grep -E 'error|lost [1-9]' "$out/sub" | tail -1)" >&2
  fi
}

# latency STACK SIZE DOMAIN -> "p50 p99" (us, medians over the per-second lines)
latency() { bench_latency "${cmd[$1]}" "$2" "$3"; }

echo "bench-sweep: $rounds rounds, ${secs}s per measurement, stacks ${stacks[*]}, loopback in a private netns," \
  "$(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg)"
# Rows of $out/tp: "size stack kS/s Mb/s cpu"; of $out/lat: "size stack p50 p99".
for r in $(seq 1 "$rounds"); do
  for size in $sizes; do
    for s in "${stacks[@]}"; do
      domain=$(((domain + 1) % 200)); echo "$size $s $(throughput "$s" "$size" "$domain")" >>"$out/tp"
    done
  done
  for size in $lat_sizes; do
    for s in "${stacks[@]}"; do
      domain=$(((domain + 1) % 200)); echo "$size $s $(latency "$s" "$size" "$domain")" >>"$out/lat"
    done
  done
  echo "round $r done (load $(cut -d' ' -f1 /proc/loadavg))"
done

median() { bench_median "$@"; }
ratio() { bench_ratio "$@"; }

printf '\nthroughput, reliable keep-all, medians over %d rounds (kS/s | Mb/s | CPU s per 1M samples, pub+sub)\n' "$rounds"
printf '%-6s' size
for s in "${stacks[@]}"; do printf ' %28s' "$s"; done
for s in "${stacks[@]:1}"; do printf ' %12s' "ours/$s"; done
echo
for size in $sizes; do
  printf '%-6s' "$size"
  for s in "${stacks[@]}"; do
    printf ' %28s' "$(median "$out/tp" "$size" "$s" 3) | $(median "$out/tp" "$size" "$s" 4) | $(median "$out/tp" "$size" "$s" 5)"
  done
  o=$(median "$out/tp" "$size" "${stacks[0]}" 3)
  for s in "${stacks[@]:1}"; do printf ' %12s' "$(ratio "$o" "$(median "$out/tp" "$size" "$s" 3)")"; done
  echo
done

printf '\nlatency, half round trip, medians over %d rounds (p50 | p99 us)\n' "$rounds"
printf '%-6s' size
for s in "${stacks[@]}"; do printf ' %16s' "$s"; done
for s in "${stacks[@]:1}"; do printf ' %16s' "ours/$s p50|p99"; done
echo
for size in $lat_sizes; do
  printf '%-6s' "$size"
  for s in "${stacks[@]}"; do printf ' %16s' "$(median "$out/lat" "$size" "$s" 3) | $(median "$out/lat" "$size" "$s" 4)"; done
  o50=$(median "$out/lat" "$size" "${stacks[0]}" 3)
  o99=$(median "$out/lat" "$size" "${stacks[0]}" 4)
  for s in "${stacks[@]:1}"; do
    printf ' %16s' "$(ratio "$o50" "$(median "$out/lat" "$size" "$s" 3)")|$(ratio "$o99" "$(median "$out/lat" "$size" "$s" 4)")"
  done
  echo
done
