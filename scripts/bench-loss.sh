#!/usr/bin/env bash
# A reliable 1 KiB stream offered at 20 kHz through a lossy link: two network namespaces joined by a veth
# pair, 30% of incoming UDP datagrams dropped at random in each (iptables statistic match; this kernel has no
# netem). Publisher in one namespace, subscriber in the other; the figure is what the subscriber received,
# complete and in order, against what was offered (rate x duration). Ours (dds-perf) and Cyclone 11's
# ddsperf in the same set-up, one after the other. A benchmark, not a timed test. Needs root and iptables
# (apt-get install iptables); the namespaces are deleted on exit.
#
#   scripts/bench-loss.sh                       # 30% loss, 20 kHz, 20 s, ours then Cyclone 11
#   LOSS=0.05 SECS=10 STACKS=ours scripts/bench-loss.sh
set -euo pipefail
cd "$(dirname "$0")/.."
loss=${LOSS:-0.3}
rate=${RATE:-20000}
secs=${SECS:-20}
size=${SIZE:-1k}
stacks=${STACKS:-ours cy11}
cy11_root=${CYCLONE11:-../shared/cyclonedds-11.0.1}
command -v iptables >/dev/null || { echo "bench-loss: iptables missing (apt-get install iptables)" >&2; exit 2; }
[[ $(id -u) -eq 0 ]] || { echo "bench-loss: needs root (ip netns)" >&2; exit 2; }
ours=$(pwd)/target/release/dds-perf
[[ -x $ours ]] || cargo build --release -p dds-examples --bin dds-perf
tag=dl$$
a=${tag}a b=${tag}b
tmp=$(mktemp -d)
cleanup() {
  for p in $(cat "$tmp"/pids 2>/dev/null); do kill "$p" 2>/dev/null || true; done
  ip netns del "$a" 2>/dev/null || true
  ip netns del "$b" 2>/dev/null || true
  rm -rf "$tmp"
}
trap cleanup EXIT

ip netns add "$a"
ip netns add "$b"
ip link add "${tag}va" netns "$a" type veth peer name "${tag}vb" netns "$b"
for ns in "$a" "$b"; do
  ip -n "$ns" link set lo up
done
ip -n "$a" addr add 10.77.0.1/24 dev "${tag}va"
ip -n "$b" addr add 10.77.0.2/24 dev "${tag}vb"
ip -n "$a" link set "${tag}va" up multicast on
ip -n "$b" link set "${tag}vb" up multicast on
ip -n "$a" route add 239.0.0.0/8 dev "${tag}va"
ip -n "$b" route add 239.0.0.0/8 dev "${tag}vb"
for ns in "$a" "$b"; do
  ip netns exec "$ns" iptables -A INPUT -p udp -m statistic --mode random --probability "$loss" -j DROP
done

source scripts/cyclone11.sh

# run STACK -> prints "received lost-reported write-timeouts"
run() {
  local prog iface_a=${tag}va iface_b=${tag}vb
  case $1 in
    ours) prog=$ours ;;
    cy11) prog=$(cyclone11_ddsperf "$cy11_root" "$tmp") ;;
    *) echo "bench-loss: unknown stack $1" >&2; return 2 ;;
  esac
  local uri='<General><Interfaces><NetworkInterface name="IF"/></Interfaces></General>'
  ip netns exec "$a" env DDS_INTERFACE="$iface_a" CYCLONEDDS_URI="${uri/IF/$iface_a}" \
    "$prog" -D $((secs + 6)) sub >"$tmp/sub" 2>&1 &
  echo $! >>"$tmp/pids"
  local sub=$!
  sleep 1
  ip netns exec "$b" env ${PUB_ENV:-} DDS_INTERFACE="$iface_b" CYCLONEDDS_URI="${uri/IF/$iface_b}" \
    "$prog" -D "$secs" pub "${rate}Hz" size "$size" >"$tmp/pub" 2>&1 || true
  wait "$sub" || true
  local got timeouts
  got=$(awk '/ size .* total / { for (i = 1; i <= NF; i++) if ($i == "total") t = $(i+1) } END { print t + 0 }' "$tmp/sub")
  timeouts=$(grep -c 'write error: timeout' "$tmp/pub" || true)
  echo "$got $timeouts"
}

offered=$((rate * secs))
echo "bench-loss: ${loss} loss each way (iptables), ${size} reliable keep-all offered at ${rate} Hz for ${secs} s = ${offered} samples"
printf '%-8s %12s %10s %16s\n' stack received fraction "write timeouts"
for s in $stacks; do
  read -r got timeouts < <(run "$s")
  printf '%-8s %12s %9.1f%% %16s\n' "$s" "$got" "$(awk -v g="$got" -v o="$offered" 'BEGIN { print 100 * g / o }')" "$timeouts"
done
