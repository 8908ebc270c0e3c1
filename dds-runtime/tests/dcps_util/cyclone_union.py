#!/usr/bin/env python3
"""Cyclone DDS 11 (python cyclonedds) peer with a keyed struct holding a @final union, for
dcps_dynamic_cyclone.rs. Its type objects number union members from 0 (Cyclone 11), ours from 1 (XTypes 1.3,
and Cyclone after 11.0.1): the endpoints match through TypeLookup and assignability, not identical ids.

  cyclone_union.py sub COUNT   -- prints each valid sample as one JSON line, exits after COUNT of them
  cyclone_union.py pub         -- writes ids 1..4 (union cases a, b, a, b), then disposes 2 and unregisters 3;
                                  keeps its writer alive until stdin closes
Both wait up to 20 s for a match. Reliable, transient-local, keep-last 10.
"""
import json
import os
import sys
import time
from dataclasses import dataclass

from cyclonedds.core import Policy, Qos
from cyclonedds.domain import DomainParticipant
from cyclonedds.idl import IdlStruct, IdlUnion
from cyclonedds.idl.annotations import final, key
from cyclonedds.idl.types import case, int32
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration

from peer import log, wait_match


@final
class Choice(IdlUnion, discriminator=int32, typename="xu::Choice"):
    a: case[1, int32]
    b: case[2, str]


@dataclass
@final
class Holder(IdlStruct, typename="xu::Holder"):
    id: int32
    key("id")
    c: Choice


QOS = Qos(
    Policy.Reliability.Reliable(duration(seconds=1)),
    Policy.Durability.TransientLocal,
    Policy.History.KeepLast(10),
)


def publish(dp, tp):
    w = DataWriter(dp, tp, qos=Qos(*QOS, Policy.WriterDataLifecycle(autodispose=False)))
    wait_match(w.get_publication_matched_status, "pub")
    for i in range(1, 5):
        w.write(Holder(id=i, c=Choice(a=10 * i) if i % 2 else Choice(b=f"s{i}")))
    w.dispose(Holder(id=2, c=Choice(a=0)))
    w.unregister_instance(Holder(id=3, c=Choice(a=0)))
    w.wait_for_acks(duration(seconds=5))
    log("pub: done")
    sys.stdin.read()


def subscribe(dp, tp, count):
    r = DataReader(dp, tp, qos=QOS)
    deadline, got = time.time() + 20, 0
    while got < count and time.time() < deadline:
        for s in r.take(N=100):
            if s.sample_info.valid_data:
                print(json.dumps({"id": s.id, "d": s.c.discriminator, "v": s.c.value}), flush=True)
                got += 1
        time.sleep(0.01)
    log(f"sub: got {got}")
    sys.exit(0 if got >= count else 3)


def main():
    dp = DomainParticipant(int(os.environ.get("DDS_DOMAIN_ID", "0")))
    tp = Topic(dp, "UnionTopic", Holder)
    if sys.argv[1] == "pub":
        publish(dp, tp)
    else:
        subscribe(dp, tp, int(sys.argv[2]))


if __name__ == "__main__":
    main()
