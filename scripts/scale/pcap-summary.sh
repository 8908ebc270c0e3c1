#!/usr/bin/env bash
# What the nodes of a scale run sent, from a capture on the bridge ports made by `CAPTURE=dir
# scripts/bench-scale.sh`: a frame sent by node i enters the bridge at port p<i> and leaves at every port it is
# delivered to, so only frames seen at the sender's own port are counted (10.77.0.i on p<i>).
#
#   scripts/scale/pcap-summary.sh FILE.pcapng NODES
#
# Prints datagrams and UDP payload bytes, split unicast/multicast, then RTPS submessages by kind and by the
# writer entity kind they concern (SPDP/SEDP/participant message/user), and datagrams per node.
set -euo pipefail
file=$1 nodes=$2
tshark -r "$file" -o rtps.enable_max_dissection_info_elements:FALSE -T fields -E separator=';' \
  -e frame.interface_name -e ip.src -e ip.dst -e udp.length -e rtps.sm.id -e rtps.sm.wrEntityId \
  -e rtps.sm.flags 2>/dev/null |
  python3 -c '
import collections, sys
nodes = int(sys.argv[1])
dg = collections.Counter(); by = collections.Counter(); per_node = collections.Counter(); byte = collections.Counter()
names = {0x15: "DATA", 0x16: "DATA_FRAG", 0x07: "HEARTBEAT", 0x06: "ACKNACK", 0x08: "GAP", 0x13: "HEARTBEAT_FRAG",
         0x12: "NACK_FRAG", 0x0e: "INFO_DST", 0x09: "INFO_TS", 0x01: "PAD", 0x0c: "INFO_SRC"}
def ent(e):
    try:
        v = int(e, 16)
    except ValueError:
        return "?"
    return {0x2c2: "sedp-topic", 0x2c7: "sedp-topic", 0x100c2: "spdp", 0x3c2: "sedp-pub", 0x4c2: "sedp-sub", 0x200c2: "p2p", 0x100c7: "spdp",
            0x3c7: "sedp-pub", 0x4c7: "sedp-sub", 0x200c7: "p2p"}.get(v, "user" if v & 0xc0 == 0 else "builtin")
for line in sys.stdin:
    f = line.rstrip("\n").split(";")
    if len(f) < 7 or not f[1] or not f[3]:
        continue
    iface, src, dst, ulen, ids, wrs, flags = f
    if iface != "p" + src.rsplit(".", 1)[-1]:
        continue
    mc = "multicast" if int(dst.split(".")[0]) >= 224 else "unicast"
    dg[mc] += 1; byte[mc] += int(ulen) - 8; per_node[src] += 1
    ids = ids.split(","); wrs = wrs.split(",")
    # tshark gives writer ids only for submessages that carry one: pair them in order.
    wi = iter(wrs)
    for s, fl in zip(ids, flags.split(",")):
        k = names.get(int(s, 16))
        if k is None or k in ("INFO_DST", "INFO_TS", "PAD", "INFO_SRC"):
            continue
        w = ent(next(wi, "?"))
        if k in ("HEARTBEAT", "ACKNACK") and int(fl, 16) & 2:
            k += "(F)"
        by[(k, w, mc)] += 1
uc, mc = dg["unicast"], dg["multicast"]
print(f"datagrams: {uc + mc} ({uc} unicast, {mc} multicast), UDP payload bytes: {sum(byte.values())}")
for (k, w, mc), n in sorted(by.items()):
    print(f"  {k:<14} {w:<9} {mc:<9} {n:>8}")
print("datagrams per node:", " ".join(str(per_node[k]) for k in sorted(per_node)))
' "$nodes"
