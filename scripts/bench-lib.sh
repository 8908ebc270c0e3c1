# Sourced by the benchmark scripts (bench-sweep.sh, bench-latency.sh): one ping/pong measurement and the
# medians and ratios of their tables. Callers set $out (a scratch directory) and $secs (seconds per
# measurement).

# bench_latency PROG SIZE DOMAIN -> "p50 p99" (us): `PROG pong` <- `PROG ping size SIZE`, the medians over the
# ping's per-second lines of the "50%" and "99%" columns (half round trip), skipping the first second.
bench_latency() {
  local prog=$1 size=$2 dom=$3
  $prog -i "$dom" -D $((secs + 1)) pong >"$out/pong" 2>&1 &
  local pong=$!
  sleep 0.5
  $prog -i "$dom" -D "$secs" ping size "$size" >"$out/ping" 2>&1 || true
  wait "$pong" || true
  grep -E ' mean .*us .* cnt ' "$out/ping" | tail -n +2 | awk '
    { for (i = 1; i <= NF; i++) { if ($i == "50%") p50[n] = $(i+1) + 0; if ($i == "99%") p99[n] = $(i+1) + 0 } n++ }
    function median(a, n,   i, j, t) { for (i = 0; i < n; i++) for (j = i + 1; j < n; j++) if (a[j] < a[i]) { t = a[i]; a[i] = a[j]; a[j] = t }
                                       return n ? a[int(n / 2)] : 0 }
    END { printf "%.1f %.1f\n", median(p50, n), median(p99, n) }'
}

# bench_median FILE SIZE STACK COLUMN -> the median of that column over the rows "size stack ..." of FILE
bench_median() {
  awk -v z="$2" -v s="$3" -v c="$4" '$1 == z && $2 == s { print $c }' "$1" | sort -g |
    awk '{ v[NR] = $1 } END { if (NR) print v[int((NR + 1) / 2)]; else print 0 }'
}

# bench_ratio A B -> "A/Bx", or n/a when B is 0
bench_ratio() { awk -v a="$1" -v b="$2" 'BEGIN { if (b > 0) printf "%.2fx", a / b; else print "n/a" }'; }
