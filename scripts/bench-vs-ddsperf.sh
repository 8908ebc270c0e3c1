#!/usr/bin/env bash
# Throughput and latency of dds-perf (our stack) against Cyclone's ddsperf, in the same run, on loopback
# inside a private network namespace. Not a timed test: a measurement to read.
#
#   scripts/bench-vs-ddsperf.sh            # 3 rounds, 10 s per measurement
#   BENCH_SECONDS=20 BENCH_ROUNDS=5 scripts/bench-vs-ddsperf.sh
#
# Each round measures both stacks back to back (ours, then ddsperf), so that drifts of a shared machine hit
# both; the table gives the median over the rounds of each figure and of each round's ratio.
#
# Throughput: 1 KiB samples, reliable keep-all, two processes: `X pub size 1k` -> `X sub`; the figure is
#   the mean of the per-second "rate ... kS/s" lines after a 2 s warm-up.
# Latency: ping/pong with the smallest KS payload, two processes: `X pong` <- `X ping`; the figures are
#   the medians over the per-second lines of ddsperf's "50%" and "99%" columns (half round trip, us).
set -euo pipefail
cd "$(dirname "$0")/.."
if [[ "${DDS_IN_NETNS:-}" != 1 ]]; then
  exec scripts/isolated "$0" "$@"
fi

secs=${BENCH_SECONDS:-10}
rounds=${BENCH_ROUNDS:-3}
ours=target/release/dds-perf
theirs=${DDSPERF:-$(command -v ddsperf || true)}
if [[ ! -x $ours ]]; then
  cargo build --release -p dds-examples --bin dds-perf
fi
if [[ -z $theirs ]]; then
  echo "bench-vs-ddsperf: ddsperf not found (apt-get install cyclonedds-tools)" >&2
  exit 2
fi
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

# throughput PROG DOMAIN -> prints kS/s and Mb/s means
throughput() {
  local prog=$1 dom=$2
  "$prog" -i "$dom" -D $((secs + 1)) sub >"$out/sub.$dom" 2>&1 &
  local sub=$!
  sleep 0.5
  "$prog" -i "$dom" -D "$secs" pub size 1k >"$out/pub.$dom" 2>&1 || true
  wait "$sub" || true
  awk '/ size .* total .* rate / { n++; if (n > 2) { for (i = 1; i <= NF; i++) { if ($i == "rate") { s += $(i+1); m += $(i+3); c++ } } } }
       END { if (c) printf "%.1f %.0f %d\n", s / c, m / c, c; else print "0 0 0" }' "$out/sub.$dom"
}

# latency PROG DOMAIN -> prints median p50 and median p99 (us)
latency() {
  local prog=$1 dom=$2
  "$prog" -i "$dom" -D $((secs + 1)) pong >"$out/pong.$dom" 2>&1 &
  local pong=$!
  sleep 0.5
  "$prog" -i "$dom" -D "$secs" ping >"$out/ping.$dom" 2>&1 || true
  wait "$pong" || true
  grep -E ' mean .*us .* cnt ' "$out/ping.$dom" | tail -n +2 | awk '
    { for (i = 1; i <= NF; i++) { if ($i == "50%") p50[n] = $(i+1) + 0; if ($i == "99%") p99[n] = $(i+1) + 0 } n++ }
    function median(a, n,   i, j, t) { for (i = 0; i < n; i++) for (j = i + 1; j < n; j++) if (a[j] < a[i]) { t = a[i]; a[i] = a[j]; a[j] = t }
                                       return n ? a[int(n / 2)] : 0 }
    END { printf "%.1f %.1f %d\n", median(p50, n), median(p99, n), n }'
}

echo "bench-vs-ddsperf: $rounds rounds, ${secs}s per measurement, loopback in a private netns, $(nproc) cores"
ratio() { awk -v a="$1" -v b="$2" 'BEGIN { if (b > 0) printf "%.2f", a / b; else print "n/a" }'; }
rows=$out/rounds
for r in $(seq 1 "$rounds"); do
  read -r our_ks our_mb our_n < <(throughput "$ours" 201)
  read -r cy_ks cy_mb cy_n < <(throughput "$theirs" 202)
  read -r our_p50 our_p99 our_ln < <(latency "$ours" 203)
  read -r cy_p50 cy_p99 cy_ln < <(latency "$theirs" 204)
  echo "$our_ks $cy_ks $(ratio "$our_ks" "$cy_ks") $our_mb $cy_mb $(ratio "$our_mb" "$cy_mb")" \
    "$our_p50 $cy_p50 $(ratio "$our_p50" "$cy_p50") $our_p99 $cy_p99 $(ratio "$our_p99" "$cy_p99")" >>"$rows"
  printf 'round %d: throughput %s vs %s kS/s, p50 %s vs %s us, p99 %s vs %s us (%s/%s, %s/%s seconds)\n' \
    "$r" "$our_ks" "$cy_ks" "$our_p50" "$cy_p50" "$our_p99" "$cy_p99" "$our_n" "$cy_n" "$our_ln" "$cy_ln"
  for f in "$out"/sub.201 "$out"/ping.203; do
    if grep -q -E 'error|lost [1-9]' "$f"; then
      echo "note: round $r: $(basename "$f") reported errors or loss:"; grep -E 'error|lost [1-9]' "$f" | tail -3
    fi
  done
done

# median COLUMN -> the median of that column over the rounds
median() { sort -g <(cut -d' ' -f"$1" "$rows") | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }
row() { printf '%-34s %14s %14s %10s\n' "$1" "$(median "$2")" "$(median $(($2 + 1)))" "$(median $(($2 + 2)))"; }
printf '\nmedians over %d rounds\n%-34s %14s %14s %10s\n' "$rounds" "" "dds-perf" "ddsperf" "ours/theirs"
row "throughput 1 KiB reliable (kS/s)" 1
row "throughput 1 KiB reliable (Mb/s)" 4
row "latency p50, half round trip (us)" 7
row "latency p99, half round trip (us)" 10
