#!/usr/bin/env python3
"""Cyclone DDS 11 (python cyclonedds) peer for dcps_dynamic_api_cyclone.rs, on a topic (the second argument,
`BeatTopic` by default) of a keyed `xs::Beat`. Reliable, volatile, keep-last 8. It prints one line per event
on stdout and exits when stdin closes.

  cyclone_dynapi.py reader [TOPIC]  -- a reader requesting MANUAL_BY_TOPIC liveliness with a 1 s lease. Prints
                               `matched`, `sample ID N` for data, `state ID disposed|no_writers` for an
                               instance state change without data, `liveliness ALIVE NOT_ALIVE` on each
                               liveliness change, `incompatible POLICY_ID`, and `writer deadline MS|inf
                               strength N` whenever the matched writer's announced QoS changes.
  cyclone_dynapi.py writer [TOPIC]  -- a writer offering a 300 ms deadline and MANUAL_BY_TOPIC liveliness
                               with a 600 ms lease. Waits for a match, prints `matched`, writes id 1 five
                               times 100 ms apart, then writes nothing more.
"""
import os
import queue
import sys
import threading
import time

from cyclonedds.core import InstanceState, Policy, Qos
from cyclonedds.domain import DomainParticipant
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration

from peer import Beat, log, wait_match


def out(line):
    print(line, flush=True)


def base_qos(*extra):
    return Qos(
        Policy.Reliability.Reliable(duration(seconds=1)),
        Policy.History.KeepLast(8),
        *extra,
    )


def stdin_lines():
    """The lines of stdin, then None at its end, through a queue (the main loop polls)."""
    q = queue.Queue()

    def pump():
        for line in sys.stdin:
            q.put(line.strip())
        q.put(None)

    threading.Thread(target=pump, daemon=True).start()
    return q


class Watched:
    """A reader's events, printed once each as they happen."""

    def __init__(self, reader):
        self.r = reader
        self.matched = False
        self.ids = {}
        self.announced = None

    def poll(self):
        if not self.matched and self.r.get_subscription_matched_status().current_count > 0:
            self.matched = True
            out(f"matched")
        for s in self.r.take(N=32):
            info = s.sample_info
            if info.valid_data:
                self.ids[info.instance_handle] = s.id
                out(f"sample {s.id} {s.n}")
            else:
                ident = self.ids.get(info.instance_handle, "?")
                state = "disposed" if info.instance_state == InstanceState.NotAliveDisposed else "no_writers"
                out(f"state {ident} {state}")
        lc = self.r.get_liveliness_changed_status()
        if lc.alive_count_change or lc.not_alive_count_change:
            out(f"liveliness {lc.alive_count} {lc.not_alive_count}")
        for h in self.r.get_matched_publications():
            d = self.r.get_matched_publication_data(h)
            if d is None:
                continue
            dl = d.qos[Policy.Deadline].deadline if Policy.Deadline in d.qos else None
            st = d.qos[Policy.OwnershipStrength].strength if Policy.OwnershipStrength in d.qos else 0
            shown = ("inf" if dl is None or dl >= 1 << 62 else f"{dl // 1_000_000}", st)
            if shown != self.announced:
                self.announced = shown
                out(f"writer deadline {shown[0]} strength {shown[1]}")
        iq = self.r.get_requested_incompatible_qos_status()
        if iq.total_count_change:
            out(f"incompatible {iq.last_policy_id}")


def reader(dp, tp):
    lease = Policy.Liveliness.ManualByTopic(duration(seconds=1))
    watched = Watched(DataReader(dp, tp, qos=base_qos(lease)))
    log("reader: ready")
    commands = stdin_lines()
    while True:
        try:
            if commands.get_nowait() is None:
                return
        except queue.Empty:
            pass
        watched.poll()
        time.sleep(0.01)


def writer(dp, tp):
    qos = base_qos(
        Policy.Deadline(duration(milliseconds=300)),
        Policy.Liveliness.ManualByTopic(duration(milliseconds=600)),
    )
    w = DataWriter(dp, tp, qos=qos)
    wait_match(w.get_publication_matched_status, "writer")
    out("matched")
    for n in range(5):
        w.write(Beat(id=1, n=n))
        time.sleep(0.1)
    log("writer: silent")
    sys.stdin.read()


def main():
    dp = DomainParticipant(int(os.environ.get("DDS_DOMAIN_ID", "0")))
    tp = Topic(dp, sys.argv[2] if len(sys.argv) > 2 else "BeatTopic", Beat)
    {"reader": reader, "writer": writer}[sys.argv[1]](dp, tp)


if __name__ == "__main__":
    main()
