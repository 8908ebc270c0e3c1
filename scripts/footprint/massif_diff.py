"""Heap growth per remote entity by allocation site, from a massif profile of the footprint probe.

usage: massif_diff.py MASSIF_OUT N [DEPTH]

Compares two detailed snapshots of scripts/footprint/massif.sh's profile: the one before the first SPDP
sample from the load was processed (nothing allocated under `on_spdp` yet), and the last one still near the
peak (before the participant is stopped and frees everything). Each allocation site is named by its first
DEPTH frames (default 2) outside the standard library and hashbrown; printed: bytes, bytes per entity, site.
"""
import re
import sys
from collections import Counter

NODE = re.compile(r"^( *)n(\d+): (\d+) (?:0x[0-9A-F]+: )?(.*)$")


def snapshots(path):
    """[(heap bytes, Counter of leaf stack -> bytes)] of the detailed snapshots."""
    out, heap, lines = [], 0, open(path).read().split("\n")
    i = 0
    while i < len(lines):
        line = lines[i]
        if line.startswith("mem_heap_B="):
            heap = int(line.split("=")[1])
        elif line == "heap_tree=detailed":
            stack, leaves = [], Counter()
            i += 1
            while i < len(lines) and (m := NODE.match(lines[i])):
                depth, children, size, name = len(m[1]), int(m[2]), int(m[3]), m[4]
                stack = stack[:depth] + [name]
                if children == 0:
                    leaves[tuple(stack)] += size
                i += 1
            out.append((heap, leaves))
            continue
        i += 1
    return out


def ours(frame):
    return not ("(library/" in frame or "(src/" in frame or frame.startswith("in ") or "UnknownInlinedFun (/" in frame)


def site(stack, depth):
    frames = [re.sub(r"<.*>", "", f) for f in stack[1:] if ours(f)]
    return " < ".join(frames[:depth]) or stack[-1]


def main():
    path, n = sys.argv[1], int(sys.argv[2])
    depth = int(sys.argv[3]) if len(sys.argv) > 3 else 2
    snaps = snapshots(path)
    loaded = [any("on_spdp" in f for s in t for f in s) for _, t in snaps]
    before = max(loaded.index(True) - 1, 0) if any(loaded) else 0
    top = max(h for h, _ in snaps)
    after = max(i for i, (h, _) in enumerate(snaps) if h >= 0.85 * top)
    growth = Counter()
    for s, v in snaps[after][1].items():
        growth[site(s, depth)] += v
    for s, v in snaps[before][1].items():
        growth[site(s, depth)] -= v
    hb, ha = snaps[before][0], snaps[after][0]
    print(f"heap {hb} -> {ha} bytes: {(ha - hb) / n:.0f} bytes per entity (snapshots {before} and {after})")
    for k, v in sorted(growth.items(), key=lambda x: -abs(x[1])):
        if abs(v) >= n * 8:
            print(f"{v:9d} {v / n:7.0f}  {k[:200]}")


main()
