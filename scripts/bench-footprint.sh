#!/usr/bin/env bash
# Footprint probe: resident memory a bare participant spends per discovered remote entity, ours against Cyclone 11.
#
#   scripts/bench-footprint.sh [writers|readers|participants] [N]     (default: writers 2000)
#
# A Cyclone DDS 11 process (PyPI binding, scripts/footprint/load.py) makes N remote writers, readers (each on its own
# topic, so nothing matches) or participants appear. The bare participant is ours (`dds-idle`) or Cyclone's
# (scripts/footprint/bare.py: the binding's libddsc). Its VmRSS is sampled from /proc every 100 ms: before the load
# (settled), the peak while the load is discovered, and the settled figure after. Reported: KB per entity
# ((settled after - before) / N) and the peak above the settled figure; then the same for RssAnon alone, the
# anonymous part of it: VmRSS also counts the pages of the program's own code (and its libraries') that the
# load runs for the first time, a fixed cost that is not per entity (about 130 KB for dds-idle). A benchmark,
# not a test; it runs inside scripts/isolated (loopback only). BARE=path/to/dds-idle probes that binary instead of a fresh release build
# (e.g. one built at an older commit, for a before/after comparison); STACKS="ours" or "cyclone" runs one side.
# DOMAIN=N: the DDS domain of our probe (default 41; Cyclone's bare participant uses N+1).
# Warm-up (both stacks alike): after a first settled sample, WARMUP (default 10; 0: none) entities of the same
# kind appear for 3 s and go, then "before" is sampled again, so the code pages and one-time tables that the
# first remote entities bring are not divided by N. Both figures are printed: per entity after the warm-up,
# and without it (from the first sample).
set -euo pipefail
cd "$(dirname "$0")/.."
if [[ -z ${DDS_ISOLATED:-} ]]; then
  [[ -n ${BARE:-} ]] || cargo build -q --release -p dds-examples --bin dds-idle
  exec env DDS_ISOLATED=1 scripts/isolated "$0" "$@"
fi
kind=${1:-writers} n=${2:-2000} warm=${WARMUP:-10}
export CYCLONEDDS_URI='<CycloneDDS><Domain><General><Interfaces><NetworkInterface name="lo"/></Interfaces></General></Domain></CycloneDDS>'
export PYTHONDONTWRITEBYTECODE=1

rss_kb() { awk '/^VmRSS/ {print $2}' "/proc/$1/status" 2>/dev/null || echo 0; }
anon_kb() { awk '/^RssAnon/ {print $2}' "/proc/$1/status" 2>/dev/null || echo 0; }

# Start a program that prints "ready pid N"; echo N.
start_bare() {
  local log=$1; shift
  "$@" >"$log" 2>&1 &
  for _ in $(seq 100); do
    grep -q '^ready pid' "$log" 2>/dev/null && { awk '/^ready pid/ {print $3; exit}' "$log"; return; }
    sleep 0.1
  done
  echo "bench-footprint: $* did not start" >&2; cat "$log" >&2; exit 1
}

# Sample $1's RSS until it has not changed by more than 1% for 3 s (or 60 s pass); echo "settled peak".
settle() {
  local pid=$1 peak=0 last=0 stable=0 r
  for _ in $(seq 600); do
    r=$(rss_kb "$pid"); ((r > peak)) && peak=$r
    if ((last > 0)) && ((r * 100 <= last * 101)) && ((r * 100 >= last * 99)); then
      stable=$((stable + 1)); ((stable >= 30)) && break
    else
      stable=0; last=$r
    fi
    sleep 0.1
  done
  echo "$r $peak $(anon_kb "$pid")"
}

probe() {
  local name=$1 domain=$2; shift 2
  local tmp pid load before after peak
  tmp=$(mktemp -d)
  pid=$(start_bare "$tmp/bare.log" "$@")
  local anon_before anon_after cold anon_cold
  read -r cold _ anon_cold < <(settle "$pid")
  # Warm-up: a few entities of the same kind appear and go, so that the code that handles them has run once
  # (its pages resident) and one-time tables exist; then "before" is sampled again.
  if ((warm > 0)); then
    python3 scripts/footprint/load.py "$domain" "$kind" "$warm" 3 >"$tmp/warm.log" 2>&1 || true
    sleep 2
  fi
  read -r before _ anon_before < <(settle "$pid")
  python3 scripts/footprint/load.py "$domain" "$kind" "$n" 120 >"$tmp/load.log" 2>&1 &
  load=$!
  local early=0 r
  for _ in $(seq 600); do
    r=$(rss_kb "$pid"); ((r > early)) && early=$r
    grep -q loaded "$tmp/load.log" && break
    sleep 0.1
  done
  read -r after peak anon_after < <(settle "$pid")
  ((early > peak)) && peak=$early
  kill "$load" "$pid" 2>/dev/null; wait "$load" "$pid" 2>/dev/null || true
  awk -v name="$name" -v b="$before" -v a="$after" -v p="$peak" -v n="$n" -v k="$kind" \
    -v ab="$anon_before" -v aa="$anon_after" -v c="$cold" -v ac="$anon_cold" -v w="$warm" 'BEGIN {
    e = substr(k, 1, length(k) - 1)
    printf "%-12s %6d %-12s  before %7d KB  after %7d KB  %6.2f KB per %s  peak %+6d KB above settled" \
      "  (anonymous: %6.2f KB per %s)\n", name, n, k, b, a, (a - b) / n, e, p - a, (aa - ab) / n, e
    if (w > 0)
      printf "%-12s %6d %-12s  without the warm-up of %d: before %7d KB  %6.2f KB per %s  (anonymous: %6.2f KB per %s)\n",
        name, n, k, w, c, (a - c) / n, e, (aa - ac) / n, e }'
  rm -rf "$tmp"
}

stacks=${STACKS:-ours cyclone}
domain=${DOMAIN:-41}
[[ $stacks == *ours* ]] && probe ours "$domain" "${BARE:-target/release/dds-idle}" -d "$domain"
[[ $stacks == *cyclone* ]] && probe cyclone-11 $((domain + 1)) python3 scripts/footprint/bare.py $((domain + 1))
exit 0
