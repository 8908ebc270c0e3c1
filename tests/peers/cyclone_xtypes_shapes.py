#!/usr/bin/env python3
"""A Cyclone DDS (python `cyclonedds` 11) peer for the OMG XTypes interoperability types (omg-dds/dds-xtypes):
the 25 shape variants, written here by hand from the suite's description, and one endpoint per (writer variant,
reader variant) pair, each on its own topic `XtPair_<w>_<r>`.

    cyclone_xtypes_shapes.py DOMAIN write|read [PAIRS]

PAIRS is `all` (the 625 pairs, the default) or a comma-separated list `w:r,...` (variants 1..=25).
`write` creates, per pair, a writer of variant w and writes one sample (key `W<w>`, x = w, y = 2w, z = 3w,
angle = 5w, shapesize 30), transient-local so a reader matched later still gets it; `read` creates, per pair, a
reader of variant r and prints every sample it takes. Both are reliable.

Printed lines (stdout, line-buffered):
    TYPEINFO <variant> <hex>           the TypeInformation Cyclone computes for each variant
    READY <endpoints>                  all endpoints exist (and, for `write`, every sample is written)
    MATCHED <total>                    the sum of the matched counts, whenever it changes
    INCOMPATIBLE <total>               the sum of the incompatible-QoS counts, whenever it changes
    SAMPLE <w> <r> <json>              (read) a sample taken, its fields in the reader's type
    PAIR <w> <r> <matched> <incompatible> <last_policy_id> <inconsistent_topic>
                                       on SIGINT/SIGTERM (or after the lifetime), one per pair
    Done.
"""

import dataclasses
import json
import os
import signal
import sys
import time
from dataclasses import dataclass

from cyclonedds.core import Policy, Qos
from cyclonedds.domain import DomainParticipant
from cyclonedds.idl import IdlStruct
from cyclonedds.idl.annotations import appendable, final, key, member_id, mutable
from cyclonedds.idl.types import bounded_str, float32, int32
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic

# Shape1: color (key), x, y, shapesize. Shape2: + angle at the end. Shape3: + z between y and shapesize.
# Shape4: shapesize moved before x. Shape5: Shape1 as base + angle. Five flavours each: no annotation (XTypes
# 1.3's default, appendable; the binding's own default would be final), @final, @appendable, @mutable, @mutable
# with explicit ids (color 10, x 20, y next (21), z 15, shapesize 30, angle 40).


@dataclass
@appendable
class Shape1Default(IdlStruct, typename="Shape1Default"):
    color: bounded_str[32]
    key("color")
    x: int32
    y: int32
    shapesize: int32


@dataclass
@appendable
class Shape2Default(IdlStruct, typename="Shape2Default"):
    color: bounded_str[32]
    key("color")
    x: int32
    y: int32
    shapesize: int32
    angle: float32


@dataclass
@appendable
class Shape3Default(IdlStruct, typename="Shape3Default"):
    color: bounded_str[32]
    key("color")
    x: int32
    y: int32
    z: int32
    shapesize: int32


@dataclass
@appendable
class Shape4Default(IdlStruct, typename="Shape4Default"):
    color: bounded_str[32]
    key("color")
    shapesize: int32
    x: int32
    y: int32


@dataclass
@appendable
class Shape5Default(Shape1Default, typename="Shape5Default"):
    angle: float32


@dataclass
@final
class Shape1Final(IdlStruct, typename="Shape1Final"):
    color: bounded_str[32]
    key("color")
    x: int32
    y: int32
    shapesize: int32


@dataclass
@final
class Shape2Final(IdlStruct, typename="Shape2Final"):
    color: bounded_str[32]
    key("color")
    x: int32
    y: int32
    shapesize: int32
    angle: float32


@dataclass
@final
class Shape3Final(IdlStruct, typename="Shape3Final"):
    color: bounded_str[32]
    key("color")
    x: int32
    y: int32
    z: int32
    shapesize: int32


@dataclass
@final
class Shape4Final(IdlStruct, typename="Shape4Final"):
    color: bounded_str[32]
    key("color")
    shapesize: int32
    x: int32
    y: int32


@dataclass
@final
class Shape5Final(Shape1Final, typename="Shape5Final"):
    angle: float32


@dataclass
@appendable
class Shape1Extensible(IdlStruct, typename="Shape1Extensible"):
    color: bounded_str[32]
    key("color")
    x: int32
    y: int32
    shapesize: int32


@dataclass
@appendable
class Shape2Extensible(IdlStruct, typename="Shape2Extensible"):
    color: bounded_str[32]
    key("color")
    x: int32
    y: int32
    shapesize: int32
    angle: float32


@dataclass
@appendable
class Shape3Extensible(IdlStruct, typename="Shape3Extensible"):
    color: bounded_str[32]
    key("color")
    x: int32
    y: int32
    z: int32
    shapesize: int32


@dataclass
@appendable
class Shape4Extensible(IdlStruct, typename="Shape4Extensible"):
    color: bounded_str[32]
    key("color")
    shapesize: int32
    x: int32
    y: int32


@dataclass
@appendable
class Shape5Extensible(Shape1Extensible, typename="Shape5Extensible"):
    angle: float32


@dataclass
@mutable
class Shape1Mutable(IdlStruct, typename="Shape1Mutable"):
    color: bounded_str[32]
    key("color")
    x: int32
    y: int32
    shapesize: int32


@dataclass
@mutable
class Shape2Mutable(IdlStruct, typename="Shape2Mutable"):
    color: bounded_str[32]
    key("color")
    x: int32
    y: int32
    shapesize: int32
    angle: float32


@dataclass
@mutable
class Shape3Mutable(IdlStruct, typename="Shape3Mutable"):
    color: bounded_str[32]
    key("color")
    x: int32
    y: int32
    z: int32
    shapesize: int32


@dataclass
@mutable
class Shape4Mutable(IdlStruct, typename="Shape4Mutable"):
    color: bounded_str[32]
    key("color")
    shapesize: int32
    x: int32
    y: int32


@dataclass
@mutable
class Shape5Mutable(Shape1Mutable, typename="Shape5Mutable"):
    angle: float32


@dataclass
@mutable
class Shape1MutableExplicitID(IdlStruct, typename="Shape1MutableExplicitID"):
    color: bounded_str[32]
    key("color")
    member_id("color", 10)
    x: int32
    member_id("x", 20)
    y: int32
    shapesize: int32
    member_id("shapesize", 30)


@dataclass
@mutable
class Shape2MutableExplicitID(IdlStruct, typename="Shape2MutableExplicitID"):
    color: bounded_str[32]
    key("color")
    member_id("color", 10)
    x: int32
    member_id("x", 20)
    y: int32
    shapesize: int32
    member_id("shapesize", 30)
    angle: float32
    member_id("angle", 40)


@dataclass
@mutable
class Shape3MutableExplicitID(IdlStruct, typename="Shape3MutableExplicitID"):
    color: bounded_str[32]
    key("color")
    member_id("color", 10)
    x: int32
    member_id("x", 20)
    y: int32
    z: int32
    member_id("z", 15)
    shapesize: int32
    member_id("shapesize", 30)


@dataclass
@mutable
class Shape4MutableExplicitID(IdlStruct, typename="Shape4MutableExplicitID"):
    color: bounded_str[32]
    key("color")
    member_id("color", 10)
    shapesize: int32
    member_id("shapesize", 30)
    x: int32
    member_id("x", 20)
    y: int32


@dataclass
@mutable
class Shape5MutableExplicitID(Shape1MutableExplicitID, typename="Shape5MutableExplicitID"):
    angle: float32
    member_id("angle", 40)


# The suite's numbering: variant k is shape (k - 1) % 5 + 1 of flavour (k - 1) / 5.
VARIANTS = [
    Shape1Default, Shape2Default, Shape3Default, Shape4Default, Shape5Default,
    Shape1Final, Shape2Final, Shape3Final, Shape4Final, Shape5Final,
    Shape1Extensible, Shape2Extensible, Shape3Extensible, Shape4Extensible, Shape5Extensible,
    Shape1Mutable, Shape2Mutable, Shape3Mutable, Shape4Mutable, Shape5Mutable,
    Shape1MutableExplicitID, Shape2MutableExplicitID, Shape3MutableExplicitID, Shape4MutableExplicitID,
    Shape5MutableExplicitID,
]

LIFETIME = 120.0
stop = False


def out(line):
    sys.stdout.write(line + "\n")
    sys.stdout.flush()


def on_signal(_sig, _frame):
    global stop
    stop = True


def topic_name(w, r):
    return f"XtPair_{w}_{r}"


def sample_of(w):
    """The sample writer variant `w` writes (the members its type lacks left out)."""
    t = VARIANTS[w - 1]
    values = {"color": f"W{w}", "x": w, "y": 2 * w, "z": 3 * w, "shapesize": 30, "angle": 5.0 * w}
    names = {f.name for f in dataclasses.fields(t)}
    return t(**{n: v for n, v in values.items() if n in names})


def parse_pairs(arg):
    if arg == "all":
        return [(w, r) for w in range(1, 26) for r in range(1, 26)]
    return [tuple(int(v) for v in p.split(":")) for p in arg.split(",") if p]


def matched(role, e):
    if role == "write":
        return e.get_publication_matched_status().current_count
    return e.get_subscription_matched_status().current_count


def incompatible(role, e):
    st = e.get_offered_incompatible_qos_status() if role == "write" else e.get_requested_incompatible_qos_status()
    return st.total_count, st.last_policy_id


def main():
    domain, role = int(sys.argv[1]), sys.argv[2]
    pairs = parse_pairs(sys.argv[3] if len(sys.argv) > 3 else "all")
    signal.signal(signal.SIGINT, on_signal)
    signal.signal(signal.SIGTERM, on_signal)
    for k, t in enumerate(VARIANTS, 1):
        t.__idl__.fill_type_data()
        out(f"TYPEINFO {k} {t.__idl__._xt_bytedata[0].hex()}")
    dp = DomainParticipant(domain)
    # One topic per variant first, so that this process knows all 25 types before it discovers the other
    # end's endpoints (XTPAIRS_NO_REGISTER=1 leaves it to the TypeLookup service).
    keep = [] if os.environ.get("XTPAIRS_NO_REGISTER") == "1" else \
        [Topic(dp, f"XtRegister_{k}", t) for k, t in enumerate(VARIANTS, 1)]
    qos = Qos(Policy.Reliability.Reliable(max_blocking_time=1000000000), Policy.History.KeepLast(1),
              Policy.Durability.TransientLocal)
    ends = []
    for (w, r) in pairs:
        t = VARIANTS[(w if role == "write" else r) - 1]
        topic = Topic(dp, topic_name(w, r), t)
        e = DataWriter(dp, topic, qos=qos) if role == "write" else DataReader(dp, topic, qos=qos)
        if role == "write":
            e.write(sample_of(w))
        ends.append((w, r, topic, e))
    out(f"READY {len(ends)}")
    total, refused, end = -1, -1, time.time() + LIFETIME
    while not stop and time.time() < end:
        now = sum(matched(role, e) for (_, _, _, e) in ends)
        if now != total:
            total = now
            out(f"MATCHED {total}")
        now = sum(incompatible(role, e)[0] for (_, _, _, e) in ends)
        if now != refused:
            refused = now
            out(f"INCOMPATIBLE {refused}")
        if role == "read":
            for (w, r, _, e) in ends:
                for s in e.take(N=10):
                    if isinstance(s, VARIANTS[r - 1]):
                        out(f"SAMPLE {w} {r} {json.dumps(dataclasses.asdict(s), sort_keys=True)}")
        time.sleep(0.1)
    for (w, r, topic, e) in ends:
        n, pol = incompatible(role, e)
        inc = topic.get_inconsistent_topic_status().total_count
        out(f"PAIR {w} {r} {matched(role, e)} {n} {pol} {inc}")
    out("Done.")
    del keep


if __name__ == "__main__":
    main()
