#!/usr/bin/env bash
# Shared-memory throughput of Cyclone DDS 0.10.2 with iceoryx (Debian packages) against our loan path,
# interleaved, 1 MiB and 4 MiB samples, writer touching only `seq` and writer filling every byte.
#   scripts/bench-cyclone-iox.sh [ROUNDS] [SECONDS]        (defaults 3 and 3)
# Needs (installs nothing): cyclonedds-dev 0.10.2 (libddsc + /usr/bin/idlc), iceoryx (iox-roudi), cc,
# and our release example built with `-F shm` (OURS, default target/release/examples/dcps_shm_throughput).
# Cyclone runs twice per size and writer: KEEP_LAST 16 (its writer never waits: the reader loses samples)
# and KEEP_LAST 1000 (lossless: the writer's loan waits for RouDi's pool; see docs/performance.md).
# Runs everything, RouDi included, in one scripts/isolated network namespace; the loopback byte
# counters before and after each Cyclone run show how much went over UDP. A benchmark, not a test.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
if [[ "${DDS_IN_NETNS:-}" != 1 ]]; then
  exec "$here/isolated" "$0" "$@"
fi
rounds=${1:-3}
secs=${2:-3}
ours=${OURS:-$here/../target/release/examples/dcps_shm_throughput}

missing=()
[[ -x /usr/bin/idlc ]] || missing+=("/usr/bin/idlc (apt-get install cyclonedds-tools or cyclonedds-dev)")
[[ -f /usr/include/dds/dds.h ]] || missing+=("/usr/include/dds/dds.h (apt-get install cyclonedds-dev)")
command -v iox-roudi >/dev/null || missing+=("iox-roudi (apt-get install iceoryx)")
command -v cc >/dev/null || missing+=("cc")
[[ -x "$ours" ]] || missing+=("$ours (cargo build --release -p dds-runtime --example dcps_shm_throughput -F shm)")
if ((${#missing[@]})); then
  printf 'bench-cyclone-iox: missing: %s\n' "${missing[@]}" >&2
  exit 1
fi

work=$(mktemp -d)
roudi_pid=
cleanup() {
  [[ -n "$roudi_pid" ]] && kill "$roudi_pid" 2>/dev/null && wait "$roudi_pid" 2>/dev/null
  rm -rf "$work"
}
trap cleanup EXIT

# Build: types from bench.idl with Debian's idlc 0.10.2, program against Debian's libddsc.
(cd "$work" && /usr/bin/idlc "$here/cyclone-iox/bench.idl" &&
  cc -O2 -Wall -I. -o iox_perf "$here/cyclone-iox/iox_perf.c" bench.c -lddsc)

# RouDi's shared memory: chunks a little above 1 MiB and 4 MiB (payload plus the iceoryx and Cyclone
# headers), more of them than a KEEP_LAST 16 reader and a writer can hold at once.
cat >"$work/roudi.toml" <<'EOF'
[general]
version = 1

[[segment]]

[[segment.mempool]]
size = 1024
count = 1000

[[segment.mempool]]
size = 1100000
count = 64

[[segment.mempool]]
size = 4400000
count = 40
EOF
iox-roudi -c "$work/roudi.toml" -l warning >"$work/roudi.log" 2>&1 &
roudi_pid=$!
sleep 1

export CYCLONEDDS_URI='<CycloneDDS><Domain><SharedMemory><Enable>true</Enable><LogLevel>warn</LogLevel></SharedMemory></Domain></CycloneDDS>'
lo_bytes() { ip -s -j link show lo | python3 -c 'import json,sys; print(json.load(sys.stdin)[0]["stats64"]["rx"]["bytes"])'; }

# One Cyclone+iceoryx run: prints "MEAN LO_BYTES RECEIVED LOST WRITTEN" (MEAN: samples/s the reader got).
# QOS "" is KEEP_LAST 16 (the reader's iceoryx queue drops the oldest when full: the writer never waits);
# keep-last-1000 makes the reader's queue longer than RouDi's pool, so the writer's loan waits for a chunk.
cyclone_run() {
  local size=$1 fill=$2 qos=$3 before after out
  before=$(lo_bytes)
  IOX_PERF_QOS=$qos "$work/iox_perf" sub "$size" >"$work/sub.out" 2>"$work/sub.err" &
  local sub=$!
  IOX_PERF_QOS=$qos "$work/iox_perf" pub "$size" "$secs" $fill 2>"$work/pub.err" >/dev/null || echo "  cyclone pub failed: $(grep iox_perf "$work/pub.err")" >&2
  wait "$sub" || true
  after=$(lo_bytes)
  out=$(tail -1 "$work/sub.out")
  grep -q 'shared memory yes' "$work/sub.err" || echo "  cyclone sub: $(cat "$work/sub.err")" >&2
  grep -q 'shared memory yes' "$work/pub.err" || echo "  cyclone pub: $(cat "$work/pub.err")" >&2
  local written
  written=$(awk '/wrote/{print $3}' "$work/pub.err")
  awk -v lo=$((after - before)) -v w="$written" '{print $2, lo, $8, $10, w}' <<<"${out//,/}"
}

# Our loan path: prints "MEAN_LOAN MEAN_LOAN_FILL" (samples/s).
ours_run() {
  local bytes=$1
  "$ours" "$bytes" "$secs" 1 loan,loan-fill | awk '$3=="loan"{l=$7} $3=="loan-fill"{f=$7} END{print l, f}'
}

median() { sort -n | awk '{a[NR]=$1} END{print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }

for size in 1 4; do
  bytes=$((size << 20))
  : >"$work/r$size"
  for ((r = 1; r <= rounds; r++)); do
    read -r ol of < <(ours_run "$bytes")
    printf 'size %d MiB round %d: ours loan %s, loan-fill %s\n' "$size" "$r" "$ol" "$of"
    line="$ol $of"
    for qos in "" keep-last-1000; do
      for fill in "" fill; do
        read -r c lo rx lost w < <(cyclone_run "$size" "$fill" "$qos")
        printf '  cyclone+iox %s %s: %s samples/s (written %s, received %s, lost %s; loopback %s B)\n' \
          "${qos:-keep-last-16}" "${fill:-seq-only}" "$c" "$w" "$rx" "$lost" "$lo"
        line+=" $c"
      done
    done
    echo "$line" >>"$work/r$size"
  done
  m() { cut -d' ' -f"$1" "$work/r$size" | median; }
  printf 'size %d MiB medians (samples/s): seq only: ours loan %s, cyclone+iox keep-last-16 %s, keep-last-1000 %s; fill: ours loan-fill %s, cyclone+iox keep-last-16 %s, keep-last-1000 %s\n' \
    "$size" "$(m 1)" "$(m 3)" "$(m 5)" "$(m 2)" "$(m 4)" "$(m 6)"
done
