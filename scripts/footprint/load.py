"""Footprint load: makes remote entities appear to a bare participant, using Cyclone DDS (PyPI binding).

usage: load.py DOMAIN KIND N SECONDS   KIND = writers | readers | participants
writers/readers: one participant with N endpoints, each on its own topic (so none is matched by anything).
participants: N participants, no endpoints.
Prints "loaded" once everything exists, then holds it for SECONDS.
"""
import sys
import time
from dataclasses import dataclass

from cyclonedds.domain import DomainParticipant
from cyclonedds.idl import IdlStruct
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic


@dataclass
class Probe(IdlStruct, typename="Probe"):
    x: int


def main() -> None:
    domain, kind, n, seconds = int(sys.argv[1]), sys.argv[2], int(sys.argv[3]), float(sys.argv[4])
    keep = []
    if kind == "participants":
        keep = [DomainParticipant(domain) for _ in range(n)]
    else:
        dp = DomainParticipant(domain)
        keep.append(dp)
        for i in range(n):
            t = Topic(dp, f"probe_{i}", Probe)
            keep.append(DataWriter(dp, t) if kind == "writers" else DataReader(dp, t))
    print("loaded", flush=True)
    time.sleep(seconds)


main()
