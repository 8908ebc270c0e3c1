#!/usr/bin/env bash
# Where a ping/pong round trip's time goes, per end and per stack: CPU (task clock, user and system), context
# switches and migrations per round trip (`perf stat`), and the system calls per round trip (`strace -c`), for
# the bare-UDP floor (`udp-floor`), ours (`dds-perf`) and Cyclone 11's ddsperf. Inside one private network
# namespace. A measurement to read, not a test.
#
#   scripts/bench-latency-profile.sh                 # 16 B; STACKS="floor ours cy11", SIZE=16, SECS=2
#
# Each stack runs `pong` and `ping size SIZE` for SECS + 3 s; after 1.5 s `perf stat` watches each end for SECS,
# and the round trips in that window come from the ping's per-second "cnt" figures. Then a second pair runs
# under `strace -c -f` on the pong end (strace slows it: only the calls per round trip are read from it).
set -euo pipefail
cd "$(dirname "$0")/.."
if [[ "${DDS_IN_NETNS:-}" != 1 ]]; then
  exec scripts/isolated "$0" "$@"
fi
size=${SIZE:-16}
secs=${SECS:-2}
stacks=${STACKS:-floor ours cy11}
out=$(mktemp -d)
trap 'kill $(jobs -p) 2>/dev/null || true; rm -rf "$out"' EXIT
source scripts/cyclone11.sh
declare -A cmd=([ours]=${OURS:-target/release/dds-perf} [floor]=${FLOOR:-target/release/udp-floor}
  [floorc]="${FLOOR:-target/release/udp-floor} connected")
[[ -n ${BASE:-} ]] && cmd[base]=$BASE
cmd[cy11]=$(cyclone11_ddsperf "${CYCLONE11:-../shared/cyclonedds-11.0.1}" "$out")

# pair PROG DOMAIN -> starts pong and ping in the background; sets $pong $ping
pair() {
  $1 -i "$2" -D $((secs + 4)) pong >"$out/pong" 2>&1 &
  pong=$!
  sleep 0.5
  $1 -i "$2" -D $((secs + 3)) ping size "$size" >"$out/ping" 2>&1 &
  ping=$!
}

# $! is the program itself: the cy11 wrapper execs ddsperf.
dom=150
printf '%-7s %-5s %10s %10s %10s %9s %9s %9s  %s\n' stack end "rt/s" "cpu us/rt" "usr us/rt" "sys us/rt" "cs/rt" "migr/rt" \
  "syscalls per round trip (pong end, strace)"
for s in $stacks; do
  dom=$((dom + 1))
  pair "${cmd[$s]}" "$dom"
  sleep 1.5
  perfs=()
  for end in pong ping; do
    perf stat -x, -e task-clock,context-switches,cpu-migrations -p "${!end}" -o "$out/stat.$end" -- sleep "$secs" &
    perfs+=($!)
  done
  # utime and stime of each end (fields 14 and 15 of /proc/PID/stat), in clock ticks.
  ut0=$(for end in pong ping; do p=${!end}; awk '{ print $14, $15 }' /proc/$p/stat; done)
  wait "${perfs[@]}"
  ut1=$(for end in pong ping; do p=${!end}; awk '{ print $14, $15 }' /proc/$p/stat; done)
  wait "$ping" "$pong" 2>/dev/null || true
  # Round trips per second: the mean of the ping's per-second counts after the first.
  rts=$(grep -E ' mean .* cnt ' "$out/ping" | tail -n +2 | awk '{ s += $NF; n++ } END { print n ? s / n : 0 }')
  tck=$(getconf CLK_TCK)
  i=0
  for end in pong ping; do
    i=$((i + 1))
    read -r u0 s0 < <(sed -n "${i}p" <<<"$ut0")
    read -r u1 s1 < <(sed -n "${i}p" <<<"$ut1")
    awk -F, -v rts="$rts" -v secs="$secs" -v s="$s" -v e="$end" -v du=$((u1 - u0)) -v ds=$((s1 - s0)) -v tck="$tck" '
      $3 == "task-clock" { tc = $1 } $3 == "context-switches" { cs = $1 } $3 == "cpu-migrations" { mg = $1 }
      END { rt = rts * secs; if (rt == 0) rt = 1
            printf "%-7s %-5s %10.0f %10.2f %10.2f %9.2f %9.2f %9.3f", s, e, rts, tc * 1e3 / rt, du / tck * 1e6 / rt, ds / tck * 1e6 / rt, cs / rt, mg / rt }' \
      "$out/stat.$end"
    echo
  done
  # System calls on the pong end (strace slows the round trip, so the ping's counts do not apply): each
  # call's count over the most frequent call's, which at 16 B is once per round trip (the read of the ping).
  dom=$((dom + 1))
  pair "${cmd[$s]}" "$dom"
  sleep 1.5
  timeout -s INT "$secs" strace -c -f -p "$pong" -o "$out/strace" 2>/dev/null || true
  wait "$ping" "$pong" 2>/dev/null || true
  awk -v s="$s" '$NF ~ /^[a-z_0-9]+$/ && $4 ~ /^[0-9]+$/ && $NF != "total" { c[$NF] = $4; if ($4 > m) m = $4 }
    END { printf "%-7s pong end, system calls per round trip:", s; for (k in c) if (c[k] / m >= 0.05) printf " %s %.2f", k, c[k] / m; print "" }' "$out/strace"
done
