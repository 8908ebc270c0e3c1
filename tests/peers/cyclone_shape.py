#!/usr/bin/env python3
"""A Cyclone DDS (python `cyclonedds` 11) peer with the command-line and output contract of the OMG
interoperability suite's `shape_main` (omg-dds/dds-rtps, srcCxx/shape_main.cxx).

Only what the interop tests use is implemented; other options are accepted and reported as
`not supported` so a test can tell a missing feature from a failure.

Printed lines (stdout, line-buffered):
    Create topic: Square
    Create writer for topic: Square color: BLUE
    Create reader for topic: Square
    on_publication_matched() topic: 'Square'  type: 'ShapeType' : matched readers 1 (change = 1)
    on_subscription_matched() topic: 'Square'  type: 'ShapeType' : matched writers 1 (change = 1)
    on_offered_incompatible_qos() topic: 'Square'  type: 'ShapeType' : 2 (DURABILITY)
    on_requested_incompatible_qos() topic: 'Square'  type: 'ShapeType' : 2 (DURABILITY)
    Square     BLUE       012 034 [30] {255}
    Square     BLUE       NOT_ALIVE_DISPOSED_INSTANCE_STATE
    Square     BLUE       NOT_ALIVE_NO_WRITERS_INSTANCE_STATE
    Done.
Exit codes follow shape_main: 0 ok, 1 bad arguments, 2 initialisation failed.
"""

import argparse
import random
import signal
import sys
import time
from dataclasses import dataclass, field

from cyclonedds.core import DDSException, InstanceState, Listener, Qos, Policy
from cyclonedds.domain import DomainParticipant
from cyclonedds.idl import IdlStruct
from cyclonedds.idl.annotations import appendable, key
from cyclonedds.idl.types import bounded_str, int32, sequence, uint8
from cyclonedds.pub import DataWriter, Publisher
from cyclonedds.sub import DataReader, Subscriber
from cyclonedds.topic import Topic
from cyclonedds.util import duration


@dataclass
@appendable
class ShapeType(IdlStruct, typename="ShapeType"):
    color: bounded_str[128]
    key("color")
    x: int32 = 0
    y: int32 = 0
    shapesize: int32 = 0
    additional_payload_size: sequence[uint8] = field(default_factory=list)


# DDS QosPolicyId_t values (DDS 1.4 §2.3.3 / XTypes 1.3) and shape_main's names for them.
POLICY_NAMES = {
    1: "USERDATA", 2: "DURABILITY", 3: "PRESENTATION", 4: "DEADLINE", 5: "LATENCYBUDGET",
    6: "OWNERSHIP", 7: "OWNERSHIPSTRENGTH", 8: "LIVELINESS", 9: "TIMEBASEDFILTER", 10: "PARTITION",
    11: "RELIABILITY", 12: "DESTINATIONORDER", 13: "HISTORY", 14: "RESOURCELIMITS",
    15: "ENTITYFACTORY", 16: "WRITERDATALIFECYCLE", 17: "READERDATALIFECYCLE", 18: "TOPICDATA",
    19: "GROUPDATA", 20: "TRANSPORTPRIORITY", 21: "LIFESPAN", 22: "DURABILITYSERVICE",
    # XTypes numbers DATA_REPRESENTATION 23; Cyclone numbers it 25 (23 is its PROPERTY policy).
    23: "DATAREPRESENTATION", 24: "TYPECONSISTENCY", 25: "DATAREPRESENTATION",
}

all_done = False


def out(line):
    sys.stdout.write(line + "\n")
    sys.stdout.flush()


def parse_args(argv):
    p = argparse.ArgumentParser(prog="cyclone_shape.py", add_help=False)
    p.add_argument("-h", "--help", action="store_true")
    p.add_argument("-v", dest="verbosity", default="e")
    p.add_argument("-P", dest="publish", action="store_true")
    p.add_argument("-S", dest="subscribe", action="store_true")
    p.add_argument("-d", dest="domain", type=int, default=0)
    p.add_argument("-b", dest="best_effort", action="store_true")
    p.add_argument("-r", dest="reliable", action="store_true")
    p.add_argument("-k", dest="depth", type=int, default=-1)
    p.add_argument("-f", dest="deadline_ms", type=int, default=0)
    p.add_argument("-s", dest="strength", type=int, default=-1)
    p.add_argument("-t", dest="topic")
    p.add_argument("-c", dest="color")
    p.add_argument("-p", dest="partition")
    p.add_argument("-D", dest="durability", default="v")
    p.add_argument("-x", dest="xcdr", default="1")
    p.add_argument("-w", dest="print_writer", action="store_true")
    p.add_argument("-z", dest="shapesize", type=int, default=20)
    p.add_argument("-R", dest="use_read", action="store_true")
    p.add_argument("--write-period", type=int, default=33)
    p.add_argument("--read-period", type=int, default=100)
    p.add_argument("--time-filter", type=int, default=0)
    p.add_argument("--lifespan", type=int, default=0)
    p.add_argument("--num-iterations", type=int, default=0)
    p.add_argument("--num-instances", type=int, default=1)
    p.add_argument("--num-topics", type=int, default=1)
    p.add_argument("--final-instance-state", default=None)
    p.add_argument("--access-scope", default=None)
    p.add_argument("--coherent", action="store_true")
    p.add_argument("--ordered", action="store_true")
    p.add_argument("--coherent-sample-count", type=int, default=0)
    p.add_argument("--additional-payload-size", type=int, default=0)
    p.add_argument("--take-read", action="store_true")
    p.add_argument("--periodic-announcement", type=int, default=0)
    p.add_argument("--datafrag-size", type=int, default=0)
    p.add_argument("--cft", default=None)
    p.add_argument("--size-modulo", type=int, default=0)
    try:
        o = p.parse_args(argv)
    except SystemExit:
        sys.exit(1)
    if o.help:
        p.print_usage()
        sys.exit(0)
    ok = True
    if o.topic is None:
        out("please specify topic name [-t]")
        ok = False
    if o.publish == o.subscribe:
        out("please specify publish [-P] or subscribe [-S]")
        ok = False
    if o.durability[:1] not in ("v", "l", "t", "p") or o.xcdr[:1] not in ("1", "2"):
        out("unrecognized value for durability or data representation")
        ok = False
    if o.final_instance_state is not None and o.final_instance_state[:1] not in ("u", "d"):
        out("unrecognized value for final-instance-state " + o.final_instance_state)
        ok = False
    if not ok:
        sys.exit(1)
    if o.publish and o.color is None:
        o.color = "BLUE"
        out('warning: color was not specified, defaulting to "BLUE"')
    return o


def unsupported(o):
    """Options this peer does not implement; shape_main prints `not supported` and fails."""
    bad = []
    if o.coherent:
        bad.append("Presentation Coherent Access")
    if o.ordered:
        bad.append("Presentation Ordered Access")
    if o.access_scope is not None and o.access_scope[:1] != "i":
        bad.append("Presentation Access Scope")
    if o.cft is not None:
        bad.append("ContentFilteredTopic expression")
    if o.num_topics != 1:
        bad.append("--num-topics")
    if o.datafrag_size:
        bad.append("--datafrag-size")
    return bad


def common_qos(o):
    policies = [
        Policy.Reliability.BestEffort if o.best_effort else Policy.Reliability.Reliable(duration(seconds=1)),
        {"v": Policy.Durability.Volatile, "l": Policy.Durability.TransientLocal,
         "t": Policy.Durability.Transient, "p": Policy.Durability.Persistent}[o.durability[:1]],
    ]
    if o.xcdr[:1] == "1":
        policies.append(Policy.DataRepresentation(use_cdrv0_representation=True))
    else:
        policies.append(Policy.DataRepresentation(use_xcdrv2_representation=True))
    if o.depth > 0:
        policies.append(Policy.History.KeepLast(o.depth))
    elif o.depth == 0:
        policies.append(Policy.History.KeepAll)
    if o.deadline_ms > 0:
        policies.append(Policy.Deadline(duration(milliseconds=o.deadline_ms)))
    if o.strength != -1:
        policies.append(Policy.Ownership.Exclusive)
    return policies


def status_listener(topic_name):
    prefix = "topic: '%s'  type: 'ShapeType'" % topic_name

    def pub_matched(_writer, status):
        out("on_publication_matched() %s : matched readers %d (change = %d)"
            % (prefix, status.current_count, status.current_count_change))

    def sub_matched(_reader, status):
        out("on_subscription_matched() %s : matched writers %d (change = %d)"
            % (prefix, status.current_count, status.current_count_change))

    def offered_incompat(_writer, status):
        pid = status.last_policy_id
        out("on_offered_incompatible_qos() %s : %d (%s)" % (prefix, pid, POLICY_NAMES.get(pid, "Unknown")))

    def requested_incompat(_reader, status):
        pid = status.last_policy_id
        out("on_requested_incompatible_qos() %s : %d (%s)" % (prefix, pid, POLICY_NAMES.get(pid, "Unknown")))

    def offered_deadline(_writer, status):
        out("on_offered_deadline_missed() %s : (total = %d, change = %d)"
            % (prefix, status.total_count, status.total_count_change))

    def requested_deadline(_reader, status):
        out("on_requested_deadline_missed() %s : (total = %d, change = %d)"
            % (prefix, status.total_count, status.total_count_change))

    return Listener(on_publication_matched=pub_matched, on_subscription_matched=sub_matched,
                    on_offered_incompatible_qos=offered_incompat,
                    on_requested_incompatible_qos=requested_incompat,
                    on_offered_deadline_missed=offered_deadline,
                    on_requested_deadline_missed=requested_deadline)


def shape_line(topic, s):
    line = "%-10s %-10s %03d %03d [%d]" % (topic, s.color, s.x, s.y, s.shapesize)
    if len(s.additional_payload_size) > 0:
        line += " {%u}" % s.additional_payload_size[-1]
    return line


def run_publisher(o, dp, topic):
    pub_policies = []
    if o.partition is not None:
        pub_policies.append(Policy.Partition([o.partition]))
    publisher = Publisher(dp, qos=Qos(*pub_policies))
    policies = common_qos(o)
    if o.strength != -1:
        policies.append(Policy.OwnershipStrength(o.strength))
    if o.lifespan > 0:
        policies.append(Policy.Lifespan(duration(milliseconds=o.lifespan)))
    if (o.final_instance_state or "")[:1] == "u":
        policies.append(Policy.WriterDataLifecycle(autodispose=False))
    out("Create writer for topic: %s color: %s" % (o.topic, o.color))
    writer = DataWriter(publisher, topic, qos=Qos(*policies), listener=status_listener(o.topic))

    width, height = 240, 270
    shape = ShapeType(color=o.color, x=random.randrange(width), y=random.randrange(height),
                      shapesize=o.shapesize,
                      additional_payload_size=[255] * o.additional_payload_size)
    xvel = (random.randrange(5) + 1) * random.choice((-1, 1))
    yvel = (random.randrange(5) + 1) * random.choice((-1, 1))
    colors = [o.color + (str(j) if j > 0 else "") for j in range(max(o.num_instances, 1))]
    n = 0
    while not all_done:
        shape.x += xvel
        shape.y += yvel
        if shape.x < 0:
            shape.x, xvel = 0, -xvel
        if shape.x > width:
            shape.x, xvel = width, -xvel
        if shape.y < 0:
            shape.y, yvel = 0, -yvel
        if shape.y > height:
            shape.y, yvel = height, -yvel
        if o.shapesize == 0:
            shape.shapesize = (shape.shapesize % o.size_modulo) + 1 if o.size_modulo > 0 else shape.shapesize + 1
        for c in colors:
            shape.color = c
            try:
                writer.write(shape)
            except DDSException as e:
                out("write failed: %s" % e)
            if o.print_writer:
                out(shape_line(o.topic, shape))
        time.sleep(o.write_period / 1000.0)
        n += 1
        if o.num_iterations and n >= o.num_iterations:
            break

    final = (o.final_instance_state or "")[:1]
    for c in colors:
        shape.color = c
        if final == "u":
            writer.unregister_instance(shape)
        elif final == "d":
            writer.dispose(shape)
    try:
        writer.wait_for_acks(duration(seconds=1))
    except DDSException:
        pass


def run_subscriber(o, dp, topic):
    sub_policies = []
    if o.partition is not None:
        sub_policies.append(Policy.Partition([o.partition]))
    subscriber = Subscriber(dp, qos=Qos(*sub_policies))
    policies = common_qos(o)
    if o.time_filter > 0:
        policies.append(Policy.TimeBasedFilter(duration(milliseconds=o.time_filter)))
    out("Create reader for topic: %s" % (o.topic + "_filtered" if o.color else o.topic))
    reader = DataReader(subscriber, topic, qos=Qos(*policies), listener=status_listener(o.topic))
    n = 0
    while not all_done:
        samples = reader.read(N=1000) if o.use_read else reader.take(N=1000)
        for s in samples:
            info = s.sample_info
            data = s.key_sample if not info.valid_data else s
            # shape_main filters with a content-filtered topic on `color`; same effect here.
            if o.color is not None and data.color != o.color:
                continue
            if info.valid_data:
                out(shape_line(o.topic, s))
            if info.instance_state == InstanceState.NotAliveNoWriters:
                out("%-10s %-10s NOT_ALIVE_NO_WRITERS_INSTANCE_STATE" % (o.topic, data.color))
            elif info.instance_state == InstanceState.NotAliveDisposed:
                out("%-10s %-10s NOT_ALIVE_DISPOSED_INSTANCE_STATE" % (o.topic, data.color))
        n += 1
        if o.num_iterations and n >= o.num_iterations:
            break
        time.sleep(o.read_period / 1000.0)


def main():
    global all_done
    o = parse_args(sys.argv[1:])

    def stop(_sig, _frame):
        global all_done
        all_done = True

    signal.signal(signal.SIGINT, stop)
    signal.signal(signal.SIGTERM, stop)

    bad = unsupported(o)
    for b in bad:
        out("    %s = not supported" % b)
    if bad:
        return 2
    try:
        dp = DomainParticipant(o.domain)
        out("Create topic: %s" % o.topic)
        topic = Topic(dp, o.topic, ShapeType)
        if o.publish:
            run_publisher(o, dp, topic)
        else:
            run_subscriber(o, dp, topic)
    except DDSException as e:
        out("failed: %s" % e)
        return 2
    out("Done.")
    return 0


if __name__ == "__main__":
    sys.exit(main())
