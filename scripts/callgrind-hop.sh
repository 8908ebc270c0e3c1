#!/usr/bin/env bash
# User-space instructions per round trip at the pong end of a ping/pong, counted by callgrind (which the
# machine's load does not move). The pong end runs under `valgrind --tool=callgrind`, the ping end natively,
# both inside one private network namespace; the counters are zeroed WARMUP seconds after the start and dumped
# WINDOW seconds later. Round trips are the calls of the pong's write in the window: `write_w_timestamp` for
# dds-perf, `process_ping` for Cyclone's ddsperf. A benchmark to read, not a timed test.
#
#   scripts/callgrind-hop.sh                              # target/release/dds-perf, 16 B
#   scripts/callgrind-hop.sh /tmp/base-dds-perf 1k        # another build, 1 KiB
#   PING=/tmp/base-dds-perf KEEP=/tmp/hop.cg scripts/callgrind-hop.sh target/release/dds-perf
#
# Prints: instructions, round trips, instructions per round trip; with TOP=N also the N costliest functions
# (inclusive) per round trip. KEEP=FILE keeps the callgrind dump (for callgrind_annotate). WRITE_FN= names the
# function whose calls count the round trips (a wrapper around Cyclone's ddsperf: WRITE_FN=process_ping);
# DOMAIN= (61), WARMUP= (5 s), WINDOW= (8 s). END=ping measures the ping end instead (PROG under callgrind
# runs `ping`, PING= names the pong's build then); its round trips are the calls of the ping's write.
# Receive polling is off (DDS_RECEIVE_SPIN_US=0 unless set): whether the polling guard lets a thread poll
# depends on the host's load of the moment, and a polling pong end counts its empty `recvmsg` attempts too
# (about 500 instructions per round trip more, session 27); with it off the count is that of a loaded host.
set -euo pipefail
export DDS_RECEIVE_SPIN_US=${DDS_RECEIVE_SPIN_US:-0}
cd "$(dirname "$0")/.."
if [[ "${DDS_IN_NETNS:-}" != 1 ]]; then
  exec scripts/isolated "$0" "$@"
fi

prog=${1:-target/release/dds-perf}
size=${2:-16}
ping=${PING:-$prog}
domain=${DOMAIN:-61}
warmup=${WARMUP:-5}
window=${WINDOW:-8}
out=$(mktemp -d)
cg=${KEEP:-$out/hop.cg}
trap 'kill $(jobs -p) 2>/dev/null || true; rm -rf "$out"' EXIT

case $(basename "$prog") in
  ddsperf*) writefn=${WRITE_FN:-process_ping} ;;
  *) writefn=${WRITE_FN:-write_w_timestamp} ;;
esac
total=$((warmup + window + 3))

end=${END:-pong}
cgrun=(valgrind --tool=callgrind --callgrind-out-file="$out/cg.%p" --compress-strings=no --compress-pos=no)
if [[ $end == ping ]]; then
  $ping -i "$domain" -D "$total" pong >"$out/ping" 2>&1 &
  pingp=$!
  sleep 1
  "${cgrun[@]}" "$prog" -i "$domain" -D $((total - 1)) ping size "$size" >"$out/pong" 2>"$out/pong.err" &
  pong=$!
else
  "${cgrun[@]}" "$prog" -i "$domain" -D "$total" pong >"$out/pong" 2>"$out/pong.err" &
  pong=$!
  sleep 1
  $ping -i "$domain" -D $((total - 1)) ping size "$size" >"$out/ping" 2>&1 &
  pingp=$!
fi
sleep "$warmup"
callgrind_control -z "$pong" >/dev/null
sleep "$window"
callgrind_control -d "$pong" >/dev/null
wait "$pingp" || true
wait "$pong" || true
# `callgrind_control -d` writes the window's dump as FILE.1; the one at exit is FILE.
dump=$out/cg.$pong.1
[[ -s $dump ]] || { echo "callgrind-hop: no dump of the window (pong: $(tail -3 "$out/pong.err"))" >&2; exit 1; }
[[ $cg != "$out/hop.cg" ]] && cp "$dump" "$cg"
ann=$(callgrind_annotate --inclusive=yes --threshold=100 "$dump" 2>/dev/null)
instr=$(grep -m1 -E 'PROGRAM TOTALS' <<<"$ann" | awk '{ gsub(",", "", $1); print $1 }')
# The calls of the write: `calls=N ...` lines under a `cfn=` naming it (strings are not compressed).
trips=$(awk -v fn="$writefn" '/^cfn=/ { tgt = index($0, fn) > 0 } /^calls=/ { if (tgt) { split($0, a, "[= ]"); n += a[2] } tgt = 0 }
  END { print n + 0 }' "$dump")
trips=${trips:-0}
echo "callgrind-hop: $(basename "$prog") $end, $size B, ${window}s window: $instr instructions, $trips round trips," \
  "$(awk -v i="$instr" -v t="$trips" 'BEGIN { if (t > 0) printf "%.0f", i / t; else print "n/a" }') per round trip"
if [[ -n ${TOP:-} ]]; then
  grep -E '^ *[0-9,]+ ' <<<"$ann" | grep -v 'PROGRAM TOTALS' | head -n "$TOP" |
    awk -v t="$trips" '{ c = $1; gsub(",", "", c); $1 = ""; $2 = ""; printf "%8.0f %s\n", c / t, $0 }'
fi
