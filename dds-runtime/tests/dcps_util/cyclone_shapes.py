#!/usr/bin/env python3
"""Tiny Cyclone DDS (python cyclonedds 11) peer for the dcps interop scratch test.

  cyclone_shapes.py pub TOPIC COLOR COUNT   -- writes COUNT samples (x = 0..COUNT-1), then disposes COLOR
  cyclone_shapes.py sub TOPIC COUNT [dispose] -- prints each received sample as one JSON line, exits after COUNT
                                               valid samples (and, with `dispose`, a NOT_ALIVE_DISPOSED one)
Both wait up to 20 s for a match. Reliable, transient-local, keep-last 100.
"""
import json
import sys
import time
from dataclasses import dataclass

from cyclonedds.core import InstanceState, Policy, Qos
from cyclonedds.domain import DomainParticipant
from cyclonedds.idl import IdlStruct
from cyclonedds.idl.annotations import appendable, key
from cyclonedds.idl.types import int32
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration

from peer import log, wait_match


@dataclass
@appendable
class ShapeType(IdlStruct, typename="ShapeType"):
    color: str
    key("color")
    x: int32
    y: int32
    shapesize: int32


QOS = Qos(
    Policy.Reliability.Reliable(duration(seconds=1)),
    Policy.Durability.TransientLocal,
    Policy.History.KeepLast(100),
)


def main():
    dp = DomainParticipant(int(__import__("os").environ.get("DDS_DOMAIN_ID", "0")))
    mode, topic_name = sys.argv[1], sys.argv[2]
    tp = Topic(dp, topic_name, ShapeType)
    deadline = time.time() + 20
    if mode == "pub":
        color, count = sys.argv[3], int(sys.argv[4])
        w = DataWriter(dp, tp, qos=QOS)
        wait_match(w.get_publication_matched_status, "pub")
        for i in range(count):
            w.write(ShapeType(color=color, x=i, y=2 * i, shapesize=30))
            time.sleep(0.01)
        w.dispose(ShapeType(color=color, x=0, y=0, shapesize=0))
        w.wait_for_acks(duration(seconds=5))
        time.sleep(0.5)
        log("pub: done")
    else:
        count = int(sys.argv[3])
        want_dispose = len(sys.argv) > 4 and sys.argv[4] == "dispose"
        disposed = False
        r = DataReader(dp, tp, qos=QOS)
        got = 0
        while (got < count or (want_dispose and not disposed)) and time.time() < deadline:
            for s in r.take(N=100):
                info = s.sample_info
                # Cyclone reports the dispose on the retained valid samples when it has some.
                disposed |= info.instance_state == InstanceState.NotAliveDisposed
                if info.valid_data:
                    print(json.dumps({"color": s.color, "x": s.x, "y": s.y, "shapesize": s.shapesize,
                                      "disposed": disposed}), flush=True)
                    got += 1
                else:
                    print(json.dumps({"state": int(info.instance_state), "disposed": disposed}), flush=True)
            time.sleep(0.01)
        log(f"sub: got {got}")
        sys.exit(0 if got >= count and (disposed or not want_dispose) else 3)


if __name__ == "__main__":
    main()
