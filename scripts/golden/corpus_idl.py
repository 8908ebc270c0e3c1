"""Writes tests/fixtures/idlc-golden/*.json: libddsc 11.0.1's bytes for types of the real IDL corpus.

The types (corpus_idl_types.py) mirror declarations in /work/shared/idl-corpus; the sample values are below. The
bytes come from the same machinery as tests/fixtures/golden (gen.py's `one_type`, oracle.py's libddsc), so the
fixture format is the same, plus `corpus_file` and `corpus_type` saying where each type is declared. The Rust
side (tests/tests/idlc_golden.rs) compiles those IDL files with idlc and compares. Run through scripts/gen-golden.
"""

import json
import math
import os
import re
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from gen import one_type  # noqa: E402
from oracle import Oracle  # noqa: E402
from corpus_idl_types import *  # noqa: E402,F401,F403 (the classes below: F405 throughout)
from corpus_idl_types import EPROSIMA, ROS  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
OUT = ROOT / "tests" / "fixtures" / "idlc-golden"
CORPUS_DIR = Path(os.environ.get("DDS_IDL_CORPUS", ROOT.parent / "shared" / "idl-corpus"))
I64_MIN, I64_MAX = -2**63, 2**63 - 1


def header(sec, nsec, frame, final_=False):
    if final_:
        return std_msgs_msg_Header_F(stamp=std_msgs_msg_Time_F(sec=sec, nanosec=nsec), frame_id=frame)
    return std_msgs_msg_Header(stamp=std_msgs_msg_Time(sec=sec, nanosec=nsec), frame_id=frame)


def ros_samples(final_):
    """The ROS samples, as @appendable types (our idlc's default) or @final ones (Cyclone idlc's default)."""
    f = "_F" if final_ else ""
    g = globals()
    Point, Quaternion, Vector3 = (g[f"geometry_msgs_msg_{n}{f}"] for n in ("Point", "Quaternion", "Vector3"))
    Pose, PoseStamped = g[f"geometry_msgs_msg_Pose{f}"], g[f"geometry_msgs_msg_PoseStamped{f}"]
    Imu = g[f"sensor_msgs_msg_Imu{f}"]
    KeyValue = g[f"diagnostic_msgs_msg_KeyValue{f}"]
    DiagnosticStatus = g[f"diagnostic_msgs_msg_DiagnosticStatus{f}"]
    suffix = ".final" if final_ else ""
    return [
        (f"geometry_msgs.msg.PoseStamped{suffix}", f"{ROS}/geometry_msgs/msg/PoseStamped.idl",
         "geometry_msgs::msg::PoseStamped", PoseStamped, [
             ("basic", PoseStamped(
                 header=header(1700000000, 123456789, "map", final_),
                 pose=Pose(position=Point(x=1.0, y=-2.0, z=3.5),
                           orientation=Quaternion(x=0.0, y=0.0, z=math.sqrt(0.5), w=math.sqrt(0.5)))))]),
        (f"sensor_msgs.msg.Imu{suffix}", f"{ROS}/sensor_msgs/msg/Imu.idl", "sensor_msgs::msg::Imu", Imu, [
            ("basic", Imu(
                header=header(-1, 999999999, "imu_link", final_),
                orientation=Quaternion(x=0.0, y=0.0, z=0.0, w=1.0),
                orientation_covariance=[float(i) for i in range(9)],
                angular_velocity=Vector3(x=0.1, y=0.2, z=0.3),
                angular_velocity_covariance=[-1.0] + [0.0] * 8,
                linear_acceleration=Vector3(x=0.0, y=0.0, z=9.81),
                linear_acceleration_covariance=[0.5 ** i for i in range(9)]))]),
        (f"diagnostic_msgs.msg.DiagnosticStatus{suffix}", f"{ROS}/diagnostic_msgs/msg/DiagnosticStatus.idl",
         "diagnostic_msgs::msg::DiagnosticStatus", DiagnosticStatus, [
             ("basic", DiagnosticStatus(
                 level=2, name="motor", message="overheat", hardware_id="hw-7",
                 values=[KeyValue(key="temp", value="97"), KeyValue(key="limit", value="90")])),
             ("empty", DiagnosticStatus(level=0, name="", message="", hardware_id="", values=[]))]),
    ]


def bm(cls, *on):
    return cls(**{f: (f in on) for f in cls.__dataclass_fields__})


def via(sample, standin):
    """`sample`, with the bytes libddsc reads taken from `standin`, a value of a type with the same wire form.

    For values the binding cannot encode: negative enumerators (it packs enums unsigned) and enums with a
    @bit_bound of 9..16 (it writes them as 1 byte in XCDR2 and 4 in XCDR1; libddsc, XTypes and we use 2). libddsc
    reads the stand-in's bytes as the real type (its topic comes from the real type's TypeInformation) and
    encodes the vectors itself, as for every other sample."""
    object.__setattr__(sample, "serialize", standin.serialize)
    return sample


# (fixture name, corpus file, IDL scoped name, class, samples). The fixture name is the Rust test's handle.
ENTRIES = [
    ("ShapeType", "omg-dds-rtps/srcCxx/shape.idl", "ShapeType", ShapeType, [
        ("blue", ShapeType(color="BLUE", x=10, y=20, shapesize=30, additional_payload_size=[])),
        ("payload", ShapeType(color="RED", x=-5, y=250, shapesize=1,
                              additional_payload_size=[1, 2, 3, 255, 0])),
        ("long_color", ShapeType(color="C" * 128, x=0, y=0, shapesize=0,
                                 additional_payload_size=[7]))]),
    ("KeyedSeq", "cyclonedds/src/tools/ddsperf/ddsperf_types.idl", "KeyedSeq", KeyedSeq, [
        ("empty", KeyedSeq(seq=1, keyval=42, baggage=[])),
        ("baggage", KeyedSeq(seq=0xffffffff, keyval=7, baggage=list(range(13))))]),
    ("Keyed256", "cyclonedds/src/tools/ddsperf/ddsperf_types.idl", "Keyed256", Keyed256, [
        ("ramp", Keyed256(seq=3, keyval=0x01020304, baggage=[(i * 7) & 0xff for i in range(248)]))]),
    ("CPUStats", "cyclonedds/src/tools/ddsperf/ddsperf_types.idl", "CPUStats", CPUStats, [
        ("two_threads", CPUStats(hostname="node-1", pid=4242, maxrss=1.5e6, vcsw=10, ivcsw=2,
                                 some_above=True, cpu=[CPUStatThread(name="main", u_pct=12, s_pct=3),
                                                       CPUStatThread(name="recv", u_pct=0, s_pct=100)])),
        ("empty", CPUStats(hostname="", pid=0, maxrss=0.0, vcsw=0, ivcsw=0, some_above=False, cpu=[]))]),
    ("root", f"{EPROSIMA}/structures.idl", "root", root, [
        ("basic", root(var_root1=root1(foo_struct=testing_1_foo(a=1, b=-2), c=0.5),
                       var_root2=root2(foo_struct=testing_2_foo(d=True), bar_struct=bar(e=-1.25))))]),
    ("InnerStructureHelperChildChild", f"{EPROSIMA}/inheritance.idl", "InnerStructureHelperChildChild",
     InnerStructureHelperChildChild, [
         ("basic", InnerStructureHelperChildChild(
             field1=-7, field2=2.5, var_child_longlong=I64_MIN, var_child_ulonglong=2**64 - 1,
             var_child_childlonglong2=1, var_childchild_ulonglong2=2))]),
    ("EnumStructure", f"{EPROSIMA}/enumerations.idl", "EnumStructure", EnumStructure, [
        ("mixed", EnumStructure(var_InnerEnumHelper=InnerEnumHelper.ENUM_VALUE_3,
                                var_scoped_InnerEnumHelper=Test_InnerEnumHelper.ENUM_VALUE_2)),
        ("first", EnumStructure(var_InnerEnumHelper=InnerEnumHelper.ENUM_VALUE_1,
                                var_scoped_InnerEnumHelper=Test_InnerEnumHelper.ENUM_VALUE_1))]),
    ("EnumWithValuesStructure", f"{EPROSIMA}/enumerations.idl", "EnumWithValuesStructure",
     EnumWithValuesStructure, [
         ("negative", via(EnumWithValuesStructure(var_enumwithvalues=EnumWithValues.ENUM_VALUE1),
                           EnumWithValuesStructure_wire(var_enumwithvalues=-3))),
         ("positive", EnumWithValuesStructure(var_enumwithvalues=EnumWithValues.ENUM_VALUE3))]),
    ("BitMaskStructure", f"{EPROSIMA}/enumerations.idl", "BitMaskStructure", BitMaskStructure, [
        ("some", BitMaskStructure(var_InnerBitMaskHelper=bm(InnerBitMaskHelper, "flag0", "flag6"))),
        ("none", BitMaskStructure(var_InnerBitMaskHelper=bm(InnerBitMaskHelper)))]),
    ("BoundedBitMaskStructure", f"{EPROSIMA}/enumerations.idl", "BoundedBitMaskStructure",
     BoundedBitMaskStructure, [
         ("all", BoundedBitMaskStructure(var_InnerBoundedBitMaskHelper=bm(
             InnerBoundedBitMaskHelper, "bflag0", "bflag1", "bflag4", "bflag6"))),
         ("one", BoundedBitMaskStructure(var_InnerBoundedBitMaskHelper=bm(
             InnerBoundedBitMaskHelper, "bflag4")))]),
    # No sample of case -2 (`second`): libddsc 11.0.1 matches a negative label of a `short` discriminator against
    # the zero-extended value (reads -2 as 65534) and selects no member, so its bytes drop the value (README.md).
    ("UnionDiscriminatorShort", f"{EPROSIMA}/unions.idl", "UnionDiscriminatorShort",
     UnionDiscriminatorShort, [
         ("first", UnionDiscriminatorShort(
             var_union_discriminator_short=Union_Discriminator_short(first=5)))]),
    # A selected default is written with the first enumerator no label uses (ENUM_VALUE_3), as libddsc and our
    # derive do; the binding's own choice (3, no enumerator) is refused by libddsc (see golden/README.md).
    ("UnionDiscriminatorEnum", f"{EPROSIMA}/unions.idl", "UnionDiscriminatorEnum", UnionDiscriminatorEnum, [
        ("first", UnionDiscriminatorEnum(var_union_discriminator_enum=Union_Discriminator_enum(first=-1))),
        ("second", UnionDiscriminatorEnum(
            var_union_discriminator_enum=Union_Discriminator_enum(second=I64_MAX))),
        ("default", UnionDiscriminatorEnum(var_union_discriminator_enum=Union_Discriminator_enum(
            discriminator=InnerEnumHelper.ENUM_VALUE_3, value=0xab)))]),
    # The default case is written with discriminator -1 (first signed value no label uses), as libddsc 11 does.
    ("UnionSeveralFieldsWithDefault", f"{EPROSIMA}/unions.idl", "UnionSeveralFieldsWithDefault",
     UnionSeveralFieldsWithDefault, [
         ("struct", UnionSeveralFieldsWithDefault(var_union_several_fields_with_default=(
             Union_Several_Fields_With_Default(a=InnerStructureHelper(field1=1, field2=2.0))))),
         ("bounded_string", UnionSeveralFieldsWithDefault(var_union_several_fields_with_default=(
             Union_Several_Fields_With_Default(c="ten chars!")))),
         ("array", UnionSeveralFieldsWithDefault(var_union_several_fields_with_default=(
             Union_Several_Fields_With_Default(d=[1, -1])))),
         ("sequence", UnionSeveralFieldsWithDefault(var_union_several_fields_with_default=(
             Union_Several_Fields_With_Default(e=[3, 2, 1])))),
         ("default", UnionSeveralFieldsWithDefault(var_union_several_fields_with_default=(
             Union_Several_Fields_With_Default(discriminator=-1, value=[10, -20, 30]))))]),
    ("KeyedInheritanceStruct", f"{EPROSIMA}/key.idl", "KeyedInheritanceStruct", KeyedInheritanceStruct, [
        ("basic", KeyedInheritanceStruct(key_short=-3, var_short=4, key_str="k", var_str="v"))]),
    ("KeyedFinal", f"{EPROSIMA}/key.idl", "KeyedFinal", KeyedFinal, [
        ("basic", KeyedFinal(key_long=1, key_short=2, key_string="three")),
        ("long_string", KeyedFinal(key_long=-1, key_short=-1, key_string="a key longer than sixteen")),
    ]),
    ("KeyedMutable", f"{EPROSIMA}/key.idl", "KeyedMutable", KeyedMutable, [
        ("basic", KeyedMutable(key_long=1, key_short=2, key_string="three")),
        ("empty", KeyedMutable(key_long=0, key_short=0, key_string=""))]),
    ("MutableInheritanceStruct", f"{EPROSIMA}/mutable.idl", "MutableInheritanceStruct",
     MutableInheritanceStruct, [
         ("basic", MutableInheritanceStruct(var_short=-1, var_str="mutable"))]),
    ("MutableExtensibilityInheritance", f"{EPROSIMA}/mutable.idl", "MutableExtensibilityInheritance",
     MutableExtensibilityInheritance, [
         ("basic", MutableExtensibilityInheritance(var_short=-1, var_long=0x01020304))]),
    ("FinalExtensibilityInheritance", f"{EPROSIMA}/final.idl", "FinalExtensibilityInheritance",
     FinalExtensibilityInheritance, [
         ("basic", FinalExtensibilityInheritance(var_short=-1, var_long=0x01020304))]),
    ("FixId", f"{EPROSIMA}/member_id.idl", "FixId", FixId, [
        ("basic", FixId(o=1, s=-2, l=3, ll=-4))]),
    ("FixHashidDefault", f"{EPROSIMA}/member_id.idl", "FixHashidDefault", FixHashidDefault, [
        ("basic", FixHashidDefault(o=0xfe, s=-2, l=3, ll=I64_MIN))]),
    ("opt_struct_align_2_optional", f"{EPROSIMA}/optional.idl", "opt_struct_align_2_optional",
     opt_struct_align_2_optional, [
         ("absent", opt_struct_align_2_optional(align=1, value=None)),
         ("inner_absent", opt_struct_align_2_optional(
             align=2, value=InnerStructOptional(s=3, l=None))),
         ("present", opt_struct_align_2_optional(
             align=0xffff, value=InnerStructOptional(s=-1, l=7)))]),
    ("ArrayMultiDimensionLiteralsShort", f"{EPROSIMA}/arrays.idl", "ArrayMultiDimensionLiteralsShort",
     ArrayMultiDimensionLiteralsShort, [
         # element [i][j][k] = 100*i + 10*j + k - 250
         ("ramp", ArrayMultiDimensionLiteralsShort(var_array_short=[
             [[100 * i + 10 * j + k - 250 for k in range(2)] for j in range(10)] for i in range(5)]))]),
    ("SequenceUnion", f"{EPROSIMA}/sequences.idl", "SequenceUnion", SequenceUnion, [
        ("mixed", SequenceUnion(var_sequence_union=[
            InnerUnionHelper(longValue=-9), InnerUnionHelper(floatValue=0.5),
            InnerUnionHelper(discriminator=-1, value=77)])),
        ("empty", SequenceUnion(var_sequence_union=[]))]),
    ("NoCommon_Module.My_Structure", f"{EPROSIMA}/sequences.idl", "NoCommon_Module::My_Structure",
     NoCommon_Module_My_Structure, [
         ("basic", NoCommon_Module_My_Structure(list=[["a", "b"], [], ["x"] * 20]))]),
]
ENTRIES += ros_samples(False)

KEYEXT_FILE = "cyclonedds/src/core/ddsc/tests/CdrStreamKeyExt.idl"
for _name in ["t1", "t1a", "t2", "t3"] + [f"t{n}{v}" for n in "456" for v in ("", "a", "b")]:
    _cls = globals()[f"KeyExt_{_name}"]
    _fields = {"a": 0x11223344}
    if "b" in _cls.__dataclass_fields__:
        _fields["b"] = globals()[f"KeyExt_nested{_name[1:]}"](a=-2)
    ENTRIES.append((f"CdrStreamKeyExt.{_name}", KEYEXT_FILE, f"CdrStreamKeyExt::{_name}", _cls,
                    [("basic", _cls(**_fields))]))

XTESTS = "cyclonedds/src/tools/idlc/xtests"
ENTRIES += [
    # The values of the C test in the same file; then the default member (discriminator -1, no label).
    ("test_struct_keys", f"{XTESTS}/test_struct_keys.idl", "test_struct_keys", test_struct_keys, [
        ("xtest", via(test_struct_keys(f1=u(u1=e.E2), f2="a", f3=u(u1=e.E3), f4=["b", "c"]),
                      test_struct_keys_wire(f1=u_wire(u1=1), f2="a", f3=u_wire(u1=2), f4=["b", "c"]))),
        ("default", via(test_struct_keys(f1=u(discriminator=-1, value=-5), f2="z", f3=u(u1=e.E1), f4=["\0", "y"]),
                        test_struct_keys_wire(f1=u_wire(discriminator=-1, value=-5), f2="z", f3=u_wire(u1=0),
                                              f4=["\0", "y"])))]),
    ("test_struct_inherit_mutable_keys", f"{XTESTS}/test_struct_inherit_mutable_keys.idl",
     "test_struct_inherit_mutable_keys", test_struct_inherit_mutable_keys, [
         ("xtest", test_struct_inherit_mutable_keys(bb1=3, b1=2, f1=1))]),
    # Negative labels only on the 32-bit discriminator: libddsc 11.0.1 reads an int8/int16 discriminator
    # zero-extended, matches no negative label (-1 is read as 255/65535), selects no member and loses its place in
    # the stream, so it has no vectors for cases -128/-1 of t1 and -32768/-1 of t2 (README.md).
    ("CdrStreamSignedUnion.t4", "cyclonedds/src/core/ddsc/tests/CdrStreamSignedUnion.idl",
     "CdrStreamSignedUnion::t4", SignedUnion_t4, [
         ("positive", SignedUnion_t4(f1=SignedUnion_t1(f3=5), f2=SignedUnion_t2(f4=1.5), f3=SignedUnion_t3(f4=2.5))),
         ("max", SignedUnion_t4(f1=SignedUnion_t1(f4=0.25), f2=SignedUnion_t2(f3=-7), f3=SignedUnion_t3(f3=7))),
         ("minus_one_32", SignedUnion_t4(f1=SignedUnion_t1(f3=1), f2=SignedUnion_t2(f3=2), f3=SignedUnion_t3(f2=-3))),
         ("min_32", SignedUnion_t4(f1=SignedUnion_t1(f4=-0.5), f2=SignedUnion_t2(f4=0.5),
                                   f3=SignedUnion_t3(f1="c")))]),
]

# Cyclone's idlc reads unannotated types as @final: the ROS types again, as a Cyclone-based (rmw_cyclonedds) peer
# has them.
ENTRIES += ros_samples(True)


def declared(file, scoped):
    """Whether the corpus file declares the type (a sanity check of the mirror; the corpus may be absent)."""
    path = CORPUS_DIR / file
    if not path.is_file():
        return None
    name = scoped.split("::")[-1]
    return re.search(rf"\b(struct|union)\s+{re.escape(name)}\b", path.read_text(errors="replace")) is not None


def main():
    OUT.mkdir(parents=True, exist_ok=True)
    oracle = Oracle()
    problems = []
    manifest = {"generator": "scripts/gen-golden (scripts/golden/corpus_idl.py)",
                "peer": "cyclonedds (Python binding + libddsc) 11.0.1", "corpus": "/work/shared/idl-corpus",
                "types": []}
    written = set()
    for fixture, file, scoped, cls, samples in ENTRIES:
        if declared(file, scoped) is False:
            problems.append(f"{fixture}: {file} declares no {scoped}")
        doc = {"corpus_file": file, "corpus_type": scoped}
        doc.update(one_type(oracle, cls, samples, problems))
        if doc["typename"] != scoped:
            problems.append(f"{fixture}: binding type name {doc['typename']} is not {scoped}")
        fname = f"{fixture}.json"
        (OUT / fname).write_text(json.dumps(doc, indent=1, ensure_ascii=False) + "\n")
        written.add(fname)
        manifest["types"].append({
            "fixture": fname, "corpus_file": file, "corpus_type": scoped, "keyed": doc["keyed"],
            "extensibility": doc["extensibility"], "samples": [s["name"] for s in doc["samples"]],
            "encodings": sorted({k for s in doc["samples"] for k in s["data"]}), "refused": doc["refused"],
        })
    manifest["problems"] = problems
    (OUT / "manifest.json").write_text(json.dumps(manifest, indent=1, ensure_ascii=False) + "\n")
    written.add("manifest.json")
    for stale in OUT.glob("*.json"):
        if stale.name not in written:
            stale.unlink()
    nfix = sum(len(t["samples"]) * len(t["encodings"]) for t in manifest["types"])
    print(f"gen-golden (idl corpus): {len(manifest['types'])} types, {nfix} sample encodings; "
          f"{len(problems)} problems")
    for p in problems:
        print("  problem:", p)
    sys.stdout.flush()
    os._exit(1 if problems else 0)  # skip interpreter teardown: the C core holds buffers we lent it


if __name__ == "__main__":
    main()
