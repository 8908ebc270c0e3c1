#!/usr/bin/env bash
# CDR encode/decode benchmark: ours vs Dust DDS 0.15 and cdr-encoding 0.11 (RustDDS's codec), then a table of
# speed-ups (their time / our time; > 1 means we are faster), same encoding against same encoding.
#
#   scripts/bench-cdr.sh              # full run (~4 min), then the table
#   scripts/bench-cdr.sh --table      # only print the table from the last run
#   scripts/bench-cdr.sh shape        # extra arguments go to criterion (here: a filter)
set -euo pipefail
cd "$(dirname "$0")/.."

# A target directory of its own: the shared one is locked by other people's builds most of the time, and a
# benchmark should not wait for (or run during) them.
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$PWD/target/bench-cdr}"

if [[ "${1:-}" != "--table" ]]; then
    cargo bench -p dds-benches --bench cdr -- "$@"
fi

python3 - "$CARGO_TARGET_DIR/criterion" <<'PY'
import json, os, sys

root = sys.argv[1]

def est(group, fn):
    p = os.path.join(root, group, fn, "new", "estimates.json")
    if not os.path.exists(p):
        return None
    e = json.load(open(p))
    return e["median"]["point_estimate"]  # ns; median resists noise from the shared machine

def fmt_t(ns):
    if ns is None:
        return "-"
    return f"{ns/1000:.2f}µs" if ns >= 1000 else f"{ns:.0f}ns"

def fmt_r(a, b):
    return "-" if a is None or b is None else f"{a/b:.2f}x"

types = ["shape", "octets1k", "nested", "wide_mutable"]
rows = []
for t in types:
    for op in ["encode", "decode"]:
        g = f"{t}_{op}"
        o1, o2 = est(g, "ours_xcdr1"), est(g, "ours_xcdr2")
        i1 = est(g, "ours_into_xcdr1")
        d1, d2 = est(g, "dust_xcdr1"), est(g, "dust_xcdr2")
        c1 = est(g, "cdr_encoding_xcdr1")
        if all(x is None for x in (o1, o2, d1, d2, c1)):
            continue
        rows.append([t, op, fmt_t(o1), fmt_t(o2), fmt_t(i1), fmt_t(d1), fmt_t(d2), fmt_t(c1),
                     fmt_r(d1, o1), fmt_r(d2, o2), fmt_r(c1, o1), fmt_r(c1, i1)])

head = ["type", "op", "ours x1", "ours x2", "ours into x1", "dust x1", "dust x2", "cdr-enc x1",
        "vs dust x1", "vs dust x2", "vs cdr-enc x1", "into vs cdr-enc x1"]
w = [max(len(str(r[i])) for r in rows + [head]) for i in range(len(head))]
line = lambda r: "| " + " | ".join(str(c).ljust(w[i]) for i, c in enumerate(r)) + " |"
print(line(head))
print("|" + "|".join("-" * (x + 2) for x in w) + "|")
for r in rows:
    print(line(r))
print("\nmedian time per sample; 'vs X' = X's time / ours (>1: ours faster). x1 = XCDR1 LE, x2 = XCDR2 LE.")
print("'ours into': deserialize_into a reused sample (decode only), as a reader that keeps its sample does.")
print("cdr-encoding on wide_mutable is plain CDR, not PL_CDR: it does less work than the other two.")
PY
