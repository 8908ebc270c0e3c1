#!/usr/bin/env python3
"""Cyclone DDS 11 (python cyclonedds) writer for the status tests of dcps_dynamic_cyclone.rs: a keyed
`xs::Beat`, offered deadline 300 ms and MANUAL_BY_TOPIC liveliness with a 600 ms lease.

  cyclone_status.py pub   -- waits up to 20 s for a match, writes id 1 five times 100 ms apart (each write
                             asserts liveliness), then writes nothing more: the reader's deadline is missed
                             and the writer's liveliness lost. Exits when stdin closes.
  cyclone_status.py sub   -- two readers of `xs::Beat`: one requesting a 1 s deadline (matches a writer
                             offering 300 ms), one requesting 100 ms (incompatible: DEADLINE). Logs the
                             first sample, exits when stdin closes.
Reliable, volatile, keep-last 1.
"""
import os
import sys
import time

from cyclonedds.core import Policy, Qos
from cyclonedds.domain import DomainParticipant
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration

from peer import Beat, log, wait_match


def sub():
    dp = DomainParticipant(int(os.environ.get("DDS_DOMAIN_ID", "0")))
    tp = Topic(dp, "BeatTopic", Beat)

    def qos(ms):
        return Qos(
            Policy.Reliability.Reliable(duration(seconds=1)),
            Policy.History.KeepLast(1),
            Policy.Deadline(duration(milliseconds=ms)),
        )

    r = DataReader(dp, tp, qos=qos(1000))
    _short = DataReader(dp, tp, qos=qos(100))
    log("sub: ready")
    deadline = time.time() + 20
    while time.time() < deadline:
        if r.take():
            log("sub: data")
            break
        time.sleep(0.05)
    sys.stdin.read()


def main():
    if sys.argv[1:] == ["sub"]:
        sub()
        return
    dp = DomainParticipant(int(os.environ.get("DDS_DOMAIN_ID", "0")))
    tp = Topic(dp, "BeatTopic", Beat)
    qos = Qos(
        Policy.Reliability.Reliable(duration(seconds=1)),
        Policy.History.KeepLast(1),
        Policy.Deadline(duration(milliseconds=300)),
        Policy.Liveliness.ManualByTopic(duration(milliseconds=600)),
    )
    w = DataWriter(dp, tp, qos=qos)
    wait_match(w.get_publication_matched_status, "pub")
    for n in range(5):
        w.write(Beat(id=1, n=n))
        time.sleep(0.1)
    log("pub: silent")
    sys.stdin.read()


if __name__ == "__main__":
    main()
