"""One Cyclone DDS 11 node of the discovery scale test: the twin of examples/src/bin/dds-scale.rs.

usage: node.py DOMAIN PARTICIPANTS TOPICS TOTAL HOLD TIMEOUT
"""
import ctypes as ct
import resource
import sys
import time
from dataclasses import dataclass

from cyclonedds.__library__ import library_path

from cyclonedds.core import Policy, Qos
from cyclonedds.util import duration
from cyclonedds.domain import DomainParticipant
from cyclonedds.idl import IdlStruct
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic


@dataclass
class Greeting(IdlStruct, typename="hello::Greeting"):
    from_: str
    text: str


class Matched(ct.Structure):
    """dds_publication_matched_status_t and dds_subscription_matched_status_t (same layout)."""

    _fields_ = [("total_count", ct.c_uint32), ("total_count_change", ct.c_int32), ("current_count", ct.c_uint32),
                ("current_count_change", ct.c_int32), ("last_handle", ct.c_uint64)]


# The binding's get_matched_subscriptions() fails with a ctypes type error in 11.0.1: read the status directly.
ddsc = ct.CDLL(library_path)


def matched(entity, func) -> int:
    st = Matched()
    if func(ct.c_int32(entity._ref), ct.byref(st)) != 0:
        raise RuntimeError("matched status")
    return st.current_count


def main() -> None:
    domain, parts, topics, total, hold, timeout = (int(a) for a in sys.argv[1:7])
    start = time.monotonic()
    qos = Qos(Policy.Reliability.Reliable(duration(milliseconds=100)))
    writers, readers, keep = [], [], []
    for _ in range(parts):
        dp = DomainParticipant(domain)
        keep.append(dp)
        for t in range(topics):
            tp = Topic(dp, f"scale_{t}", Greeting)
            writers.append(DataWriter(dp, tp, qos=qos))
            readers.append(DataReader(dp, tp, qos=qos))
    while True:
        if all(matched(w, ddsc.dds_get_publication_matched_status) >= total for w in writers) and all(
            matched(r, ddsc.dds_get_subscription_matched_status) >= total for r in readers
        ):
            break
        if time.monotonic() - start > timeout:
            print(f"timeout after {timeout} s", flush=True)
            sys.exit(1)
        time.sleep(0.05)
    ru = resource.getrusage(resource.RUSAGE_SELF)
    print(f"discovered {time.monotonic() - start:.3f} cpu {ru.ru_utime + ru.ru_stime:.2f} rss {ru.ru_maxrss}", flush=True)
    time.sleep(hold)


main()
