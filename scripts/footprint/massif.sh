#!/usr/bin/env bash
# Heap profile of the bare participant under the footprint load: where the memory per remote entity goes.
#
#   scripts/footprint/massif.sh [writers|readers|participants] [N] [OUT]     (default: participants 200 massif.out)
#
# Runs target/release/dds-idle (BARE=path for another build) under valgrind massif, makes N remote entities appear
# with scripts/footprint/load.py (Cyclone DDS 11, PyPI binding) and stops the participant while they still exist.
# Then prints the heap growth per entity by allocation site: scripts/footprint/massif_diff.py OUT (see there).
# Inside scripts/isolated (loopback only). DOMAIN=N: the DDS domain (default 41). Slow: valgrind runs the participant about 30 times slower.
set -euo pipefail
cd "$(dirname "$0")/../.."
if [[ -z ${DDS_ISOLATED:-} ]]; then
  [[ -n ${BARE:-} ]] || cargo build -q --release -p dds-examples --bin dds-idle
  exec env DDS_ISOLATED=1 scripts/isolated "$0" "$@"
fi
kind=${1:-participants} n=${2:-200} out=${3:-massif.out} domain=${DOMAIN:-41}
bare=${BARE:-target/release/dds-idle}
export CYCLONEDDS_URI='<CycloneDDS><Domain><General><Interfaces><NetworkInterface name="lo"/></Interfaces></General></Domain></CycloneDDS>'
export PYTHONDONTWRITEBYTECODE=1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
valgrind --tool=massif --detailed-freq=1 --threshold=0.05 --max-snapshots=400 --massif-out-file="$out" \
  "$bare" -d "$domain" --seconds 120 >"$tmp/bare.log" 2>&1 &
vg=$!
for _ in $(seq 300); do grep -q '^ready pid' "$tmp/bare.log" && break; sleep 0.1; done
sleep 4
# The load outlives the measurement: its entities must still be known when the participant stops.
python3 scripts/footprint/load.py "$domain" "$kind" "$n" 90 >"$tmp/load.log" 2>&1 &
load=$!
sleep 35
kill -INT "$(awk '/^ready pid/ {print $3; exit}' "$tmp/bare.log")" 2>/dev/null || true
wait "$vg" || true
kill "$load" 2>/dev/null; wait "$load" 2>/dev/null || true
python3 scripts/footprint/massif_diff.py "$out" "$n"
