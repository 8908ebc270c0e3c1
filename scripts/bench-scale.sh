#!/usr/bin/env bash
# Discovery scale test: NODES network namespaces joined by a bridge (all on this machine), one process per
# namespace with PER participants, each with a writer and a reader on each of TOPICS topics. Every endpoint waits
# until it has matched all NODES*PER participants' endpoints on its topic. Reports per implementation: the time to
# full discovery (slowest node), total CPU seconds and peak RSS summed over the nodes.
#
#   sudo scripts/bench-scale.sh [NODES=10] [PER=10] [TOPICS=10]      (default: 100 participants, 20 endpoints each)
#
# Ours: target/release/dds-scale. Cyclone 11: scripts/scale/node.py (PyPI binding). Needs root (ip netns). The
# namespaces (ddsscale-*) are deleted on exit. A benchmark, not a test. STACKS="ours" or "cyclone" runs one side;
# DDS_SCALE_BIN=path runs another dds-scale binary (e.g. one built at an older commit) without building.
# CAPTURE=dir records every frame the nodes send (tshark on the bridge ports) to dir/NAME.pcap and prints the
# datagrams, bytes and RTPS submessages each stack sent, by kind (scripts/scale/pcap-summary.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
nodes=${1:-10} per=${2:-10} topics=${3:-10}
total=$((nodes * per))
[[ -n ${DDS_SCALE_BIN:-} ]] || cargo build -q --release -p dds-examples --bin dds-scale
hub=ddsscale-hub
cleanup() {
  for i in $(seq "$nodes"); do ip netns del "ddsscale-$i" 2>/dev/null || true; done
  ip netns del "$hub" 2>/dev/null || true
}
trap cleanup EXIT
cleanup
ip netns add "$hub"
ip -n "$hub" link add br0 type bridge mcast_snooping 0
ip -n "$hub" link set br0 up
for i in $(seq "$nodes"); do
  ns=ddsscale-$i
  ip netns add "$ns"
  ip link add "v$i" netns "$ns" type veth peer name "p$i" netns "$hub"
  ip -n "$hub" link set "p$i" master br0 up
  ip -n "$ns" link set lo up
  ip -n "$ns" addr add "10.77.0.$i/24" dev "v$i"
  ip -n "$ns" link set "v$i" up multicast on
  ip -n "$ns" route add 224.0.0.0/4 dev "v$i"
done

# run NAME CMD...: one process per namespace; CMD gets the node's interface in $IFACE.
run() {
  local name=$1; shift
  local tmp pids=() slowest=0 cpu=0 rss=0 failed=0
  tmp=$(mktemp -d)
  local cap=
  if [[ -n ${CAPTURE:-} ]]; then
    mkdir -p "$CAPTURE"
    local ifs=()
    for i in $(seq "$nodes"); do ifs+=(-i "p$i"); done
    ip netns exec "$hub" tshark -q "${ifs[@]}" -f udp -w "$CAPTURE/$name.pcapng" 2>"$tmp/tshark.log" &
    cap=$!
    sleep 2
  fi
  for i in $(seq "$nodes"); do
    IFACE=v$i
    ip netns exec "ddsscale-$i" env DDS_INTERFACE="$IFACE" \
      CYCLONEDDS_URI="<CycloneDDS><Domain><General><Interfaces><NetworkInterface name=\"$IFACE\"/></Interfaces></General></Domain></CycloneDDS>" \
      "$@" >"$tmp/$i.log" 2>&1 &
    pids+=($!)
  done
  for i in "${!pids[@]}"; do
    wait "${pids[$i]}" || { failed=$((failed + 1)); echo "node $((i + 1)) failed:" >&2; tail -3 "$tmp/$((i + 1)).log" >&2; }
  done
  for i in $(seq "$nodes"); do
    read -r _ t _ c _ r < <(grep -h '^discovered' "$tmp/$i.log" || echo "x 0 x 0 x 0")
    slowest=$(awk -v a="$slowest" -v b="$t" 'BEGIN { print (b > a ? b : a) }')
    cpu=$(awk -v a="$cpu" -v b="$c" 'BEGIN { print a + b }')
    rss=$((rss + r))
  done
  if [[ -n $cap ]]; then
    sleep 1
    kill "$cap"
    wait "$cap" || true
    scripts/scale/pcap-summary.sh "$CAPTURE/$name.pcapng" "$nodes"
  fi
  printf '%-12s %3d participants x %2d endpoints: full discovery %6.2f s  cpu %7.2f s  peak rss %7d KB (sum)  %d node(s) failed\n' \
    "$name" "$total" "$((2 * topics))" "$slowest" "$cpu" "$rss" "$failed"
  rm -rf "$tmp"
}

stacks=${STACKS:-ours cyclone}
[[ $stacks == *ours* ]] && run ours "${DDS_SCALE_BIN:-target/release/dds-scale}" -d 7 --participants "$per" --topics "$topics" --total "$total" --hold 15 --timeout 120
[[ $stacks == *cyclone* ]] && run cyclone-11 python3 scripts/scale/node.py 8 "$per" "$topics" "$total" 15 120
exit 0
