"""Types from the real IDL corpus (/work/shared/idl-corpus), declared by hand with Cyclone DDS's Python binding.

Each class mirrors one IDL declaration member for member: same scoped name, member names, types, keys, ids,
annotations. Cyclone's own Python generator (`idlc -l py`) is not usable here: the wheel ships the generator
plugin but no idlc of its version, and Debian's idlc 0.10.2 crashes loading the 11.0.1 plugin.

Extensibility: the corpus files mostly carry no annotation. Our idlc applies XTypes 1.3's default, @appendable
(docs/derive.md), so the unannotated types are declared @appendable here; Cyclone's own idlc would choose @final.
Typedefs are declared as typedefs (they shape the TypeObject libddsc builds, not the wire).
"""

from dataclasses import dataclass
from typing import Optional

from cyclonedds.idl import IdlStruct, IdlUnion, IdlEnum, IdlBitmask
from cyclonedds.idl.annotations import (key, member_id, member_hash_id, external, final, appendable, mutable,
                                        nested, bit_bound, position)
from cyclonedds.idl.types import (int8, int16, int32, int64, uint8, uint16, uint32, uint64, byte, char, float32,
                                  float64, sequence, array, bounded_str, case, default, typedef)

EPROSIMA = "eprosima-dds-types-test/IDL"
ROS = "rti-ros-data-types"

# ---------------------------------------------------------------- omg-dds-rtps/srcCxx/shape.idl


@dataclass
@appendable
class ShapeType(IdlStruct, typename="ShapeType"):
    color: bounded_str[128]
    key("color")
    x: int32
    y: int32
    shapesize: int32
    additional_payload_size: sequence[uint8]


# ---------------------------------------------------------------- cyclonedds/src/tools/ddsperf/ddsperf_types.idl

@dataclass
@final
class KeyedSeq(IdlStruct, typename="KeyedSeq"):
    seq: uint32
    keyval: uint32
    key("keyval")
    baggage: sequence[byte]


@dataclass
@final
class Keyed256(IdlStruct, typename="Keyed256"):
    seq: uint32
    keyval: uint32
    key("keyval")
    baggage: array[byte, 248]


@dataclass
@final
@nested
class CPUStatThread(IdlStruct, typename="CPUStatThread"):
    name: str
    u_pct: int32
    s_pct: int32


@dataclass
@final
class CPUStats(IdlStruct, typename="CPUStats"):
    hostname: str
    key("hostname")
    pid: uint32
    key("pid")
    maxrss: float64
    vcsw: uint32
    ivcsw: uint32
    some_above: bool
    cpu: sequence[CPUStatThread]


# ---------------------------------------------------------------- eprosima: helpers/basic_inner_types.idl

class InnerEnumHelper(IdlEnum, typename="InnerEnumHelper"):
    ENUM_VALUE_1 = 0
    ENUM_VALUE_2 = 1
    ENUM_VALUE_3 = 2


@dataclass
class InnerBitMaskHelper(IdlBitmask, typename="InnerBitMaskHelper"):
    flag0: bool
    position("flag0", 0)
    flag1: bool
    position("flag1", 1)
    flag4: bool
    position("flag4", 4)
    flag6: bool
    position("flag6", 6)


@dataclass
@bit_bound(8)
class InnerBoundedBitMaskHelper(IdlBitmask, typename="InnerBoundedBitMaskHelper"):
    bflag0: bool
    position("bflag0", 0)
    bflag1: bool
    position("bflag1", 1)
    bflag4: bool
    position("bflag4", 4)
    bflag6: bool
    position("bflag6", 6)


@dataclass
@appendable
@nested
class InnerStructureHelper(IdlStruct, typename="InnerStructureHelper"):
    field1: int32
    field2: float32


@dataclass
@appendable
@nested
class InnerEmptyStructureHelper(IdlStruct, typename="InnerEmptyStructureHelper"):
    pass


@appendable
@nested
class InnerUnionHelper(IdlUnion, discriminator=int32, typename="InnerUnionHelper"):
    longValue: case[0, int32]
    floatValue: case[1, float32]
    shortValue: default[int16]


Inner_alias_bounded_string_helper = typedef["Inner_alias_bounded_string_helper", bounded_str[10]]
Inner_alias_array_helper = typedef["Inner_alias_array_helper", array[int16, 2]]
Inner_alias_sequence_helper = typedef["Inner_alias_sequence_helper", sequence[int16]]


# ---------------------------------------------------------------- eprosima: structures.idl (nested modules)

@dataclass
@appendable
class testing_1_foo(IdlStruct, typename="testing_1::foo"):
    a: int32
    b: int32


@dataclass
@appendable
class testing_2_foo(IdlStruct, typename="testing_2::foo"):
    d: bool


@dataclass
@appendable
class bar(IdlStruct, typename="bar"):
    e: float64


@dataclass
@appendable
class root1(IdlStruct, typename="root1"):
    foo_struct: testing_1_foo
    c: float32


@dataclass
@appendable
class root2(IdlStruct, typename="root2"):
    foo_struct: testing_2_foo
    bar_struct: bar


@dataclass
@appendable
class root(IdlStruct, typename="root"):
    var_root1: root1
    var_root2: root2


# ---------------------------------------------------------------- eprosima: inheritance.idl

@dataclass
@appendable
class InnerStructureHelperChild(InnerStructureHelper, typename="InnerStructureHelperChild"):
    var_child_longlong: int64
    var_child_ulonglong: uint64


@dataclass
@appendable
class InnerStructureHelperChildChild(InnerStructureHelperChild, typename="InnerStructureHelperChildChild"):
    var_child_childlonglong2: int64
    var_childchild_ulonglong2: uint64


# ---------------------------------------------------------------- eprosima: enumerations.idl

class Test_InnerEnumHelper(IdlEnum, typename="Test::InnerEnumHelper"):
    ENUM_VALUE_1 = 0
    ENUM_VALUE_2 = 1
    ENUM_VALUE_3 = 2


class EnumWithValues(IdlEnum, typename="EnumWithValues"):
    ENUM_VALUE1 = -3
    ENUM_VALUE2 = 0
    ENUM_VALUE3 = 3


@dataclass
@appendable
class EnumStructure(IdlStruct, typename="EnumStructure"):
    var_InnerEnumHelper: InnerEnumHelper
    var_scoped_InnerEnumHelper: Test_InnerEnumHelper


@dataclass
@appendable
class BitMaskStructure(IdlStruct, typename="BitMaskStructure"):
    var_InnerBitMaskHelper: InnerBitMaskHelper


@dataclass
@appendable
class BoundedBitMaskStructure(IdlStruct, typename="BoundedBitMaskStructure"):
    var_InnerBoundedBitMaskHelper: InnerBoundedBitMaskHelper


@dataclass
@appendable
class EnumWithValuesStructure(IdlStruct, typename="EnumWithValuesStructure"):
    var_enumwithvalues: EnumWithValues


# ---------------------------------------------------------------- eprosima: unions.idl

@appendable
class Union_Discriminator_short(IdlUnion, discriminator=int16, typename="Union_Discriminator_short"):
    first: case[1, int32]
    second: case[-2, int64]


@appendable
class Union_Discriminator_enum(IdlUnion, discriminator=InnerEnumHelper, typename="Union_Discriminator_enum"):
    first: case[InnerEnumHelper.ENUM_VALUE_1, int32]
    second: case[InnerEnumHelper.ENUM_VALUE_2, int64]
    third: default[byte]


@appendable
class Union_Several_Fields_With_Default(IdlUnion, discriminator=int32,
                                        typename="Union_Several_Fields_With_Default"):
    a: case[0, InnerStructureHelper]
    b: case[1, InnerEmptyStructureHelper]
    c: case[2, Inner_alias_bounded_string_helper]
    d: case[3, Inner_alias_array_helper]
    e: case[4, Inner_alias_sequence_helper]
    f: default[sequence[int16, 30]]


@dataclass
@appendable
class UnionDiscriminatorShort(IdlStruct, typename="UnionDiscriminatorShort"):
    var_union_discriminator_short: Union_Discriminator_short


@dataclass
@appendable
class UnionDiscriminatorEnum(IdlStruct, typename="UnionDiscriminatorEnum"):
    var_union_discriminator_enum: Union_Discriminator_enum


@dataclass
@appendable
class UnionSeveralFieldsWithDefault(IdlStruct, typename="UnionSeveralFieldsWithDefault"):
    var_union_several_fields_with_default: Union_Several_Fields_With_Default


# ---------------------------------------------------------------- eprosima: key.idl (`@Key` is eProsima's
# spelling of @key; idlc takes it as the key annotation)

@dataclass
@appendable
class KeyedShortStruct(IdlStruct, typename="KeyedShortStruct"):
    key_short: int16
    key("key_short")
    var_short: int16


@dataclass
@appendable
class KeyedInheritanceStruct(KeyedShortStruct, typename="KeyedInheritanceStruct"):
    key_str: str
    var_str: str


@dataclass
@final
class KeyedFinal(IdlStruct, typename="KeyedFinal"):
    key_long: int32
    member_id("key_long", 2)
    key("key_long")
    key_short: int16
    member_id("key_short", 1)
    key("key_short")
    key_string: str
    member_id("key_string", 0)
    key("key_string")


@dataclass
@mutable
class KeyedMutable(IdlStruct, typename="KeyedMutable"):
    key_long: int32
    member_id("key_long", 2)
    key("key_long")
    key_short: int16
    member_id("key_short", 1)
    key("key_short")
    key_string: str
    member_id("key_string", 0)
    key("key_string")


# ---------------------------------------------------------------- eprosima: mutable.idl

@dataclass
@mutable
class MutableShortStruct(IdlStruct, typename="MutableShortStruct"):
    var_short: int16


@dataclass
@mutable
class MutableInheritanceStruct(MutableShortStruct, typename="MutableInheritanceStruct"):
    var_str: str


# An unannotated struct takes its base's extensibility (Cyclone's idlc does so; it rejects a derived struct whose
# annotation differs from its base's), whatever the default.
@dataclass
@mutable
class MutableExtensibilityInheritance(MutableShortStruct, typename="MutableExtensibilityInheritance"):
    var_long: int32


# ---------------------------------------------------------------- eprosima: final.idl

@dataclass
@final
class FinalShortStruct(IdlStruct, typename="FinalShortStruct"):
    var_short: int16


@dataclass
@final
class FinalExtensibilityInheritance(FinalShortStruct, typename="FinalExtensibilityInheritance"):
    var_long: int32  # unannotated: @final like its base, see above


# ---------------------------------------------------------------- eprosima: member_id.idl

@dataclass
@mutable
class FixId(IdlStruct, typename="FixId"):
    o: byte
    member_id("o", 100)
    s: int16
    member_id("s", 300)
    l: int32
    member_id("l", 500)
    ll: int64


@dataclass
@mutable
class FixHashidDefault(IdlStruct, typename="FixHashidDefault"):
    o: byte
    member_hash_id("o")
    s: int16
    member_hash_id("s")
    l: int32
    member_hash_id("l")
    ll: int64


# ---------------------------------------------------------------- eprosima: optional.idl

@dataclass
@appendable
class InnerStructOptional(IdlStruct, typename="InnerStructOptional"):
    s: int16
    l: Optional[int32]


@dataclass
@appendable
class opt_struct_align_2_optional(IdlStruct, typename="opt_struct_align_2_optional"):
    align: uint16
    value: Optional[InnerStructOptional]


# ---------------------------------------------------------------- eprosima: arrays.idl (size_1 = 5, size_2 = 2)

@dataclass
@appendable
class ArrayMultiDimensionLiteralsShort(IdlStruct, typename="ArrayMultiDimensionLiteralsShort"):
    var_array_short: array[array[array[int16, 2], 10], 5]


# ---------------------------------------------------------------- eprosima: sequences.idl

@dataclass
@appendable
class SequenceUnion(IdlStruct, typename="SequenceUnion"):
    var_sequence_union: sequence[InnerUnionHelper]


Common_Module_My_Char = typedef["Common_Module::My_Char", char]
Common_Module_My_String = typedef["Common_Module::My_String", sequence[Common_Module_My_Char, 20]]
NoCommon_Module_My_AliasString = typedef["NoCommon_Module::My_AliasString", Common_Module_My_String]
NoCommon_Module_My_SequenceString = typedef["NoCommon_Module::My_SequenceString",
                                            sequence[NoCommon_Module_My_AliasString]]


@dataclass
@appendable
class NoCommon_Module_My_Structure(IdlStruct, typename="NoCommon_Module::My_Structure"):
    list: NoCommon_Module_My_SequenceString


# ---------------------------------------------------------------- rti-ros-data-types (include graph)

@dataclass
@appendable
@nested
class std_msgs_msg_Time(IdlStruct, typename="std_msgs::msg::Time"):
    sec: int32
    nanosec: uint32


@dataclass
@appendable
class std_msgs_msg_Header(IdlStruct, typename="std_msgs::msg::Header"):
    stamp: std_msgs_msg_Time
    frame_id: str


@dataclass
@appendable
class geometry_msgs_msg_Point(IdlStruct, typename="geometry_msgs::msg::Point"):
    x: float64
    y: float64
    z: float64


@dataclass
@appendable
class geometry_msgs_msg_Quaternion(IdlStruct, typename="geometry_msgs::msg::Quaternion"):
    x: float64
    y: float64
    z: float64
    w: float64


@dataclass
@appendable
class geometry_msgs_msg_Vector3(IdlStruct, typename="geometry_msgs::msg::Vector3"):
    x: float64
    y: float64
    z: float64


@dataclass
@appendable
class geometry_msgs_msg_Pose(IdlStruct, typename="geometry_msgs::msg::Pose"):
    position: geometry_msgs_msg_Point
    orientation: geometry_msgs_msg_Quaternion


@dataclass
@appendable
class geometry_msgs_msg_PoseStamped(IdlStruct, typename="geometry_msgs::msg::PoseStamped"):
    header: std_msgs_msg_Header
    pose: geometry_msgs_msg_Pose


sensor_msgs_Imu_double_array_9 = typedef["sensor_msgs::msg::sensor_msgs__Imu__double_array_9", array[float64, 9]]


@dataclass
@appendable
class sensor_msgs_msg_Imu(IdlStruct, typename="sensor_msgs::msg::Imu"):
    header: std_msgs_msg_Header
    orientation: geometry_msgs_msg_Quaternion
    orientation_covariance: sensor_msgs_Imu_double_array_9
    angular_velocity: geometry_msgs_msg_Vector3
    angular_velocity_covariance: sensor_msgs_Imu_double_array_9
    linear_acceleration: geometry_msgs_msg_Vector3
    linear_acceleration_covariance: sensor_msgs_Imu_double_array_9


@dataclass
@appendable
class diagnostic_msgs_msg_KeyValue(IdlStruct, typename="diagnostic_msgs::msg::KeyValue"):
    key: str
    value: str


@dataclass
@appendable
class diagnostic_msgs_msg_DiagnosticStatus(IdlStruct, typename="diagnostic_msgs::msg::DiagnosticStatus"):
    level: byte
    name: str
    message: str
    hardware_id: str
    values: sequence[diagnostic_msgs_msg_KeyValue]


# ---------------------------------------------------------------- cyclonedds/src/core/ddsc/tests/CdrStreamKeyExt.idl
# Keys through nested structs of every extensibility (module CdrStreamKeyExt).

@dataclass
@final
class KeyExt_t1(IdlStruct, typename="CdrStreamKeyExt::t1"):
    a: int32
    key("a")


@dataclass
@final
class KeyExt_t1a(IdlStruct, typename="CdrStreamKeyExt::t1a"):
    a: int32
    external("a")
    key("a")


@dataclass
@appendable
class KeyExt_t2(IdlStruct, typename="CdrStreamKeyExt::t2"):
    a: int32
    key("a")


@dataclass
@mutable
class KeyExt_t3(IdlStruct, typename="CdrStreamKeyExt::t3"):
    a: int32
    key("a")


@dataclass
@appendable
class KeyExt_nested4(IdlStruct, typename="CdrStreamKeyExt::nested4"):
    a: int32
    key("a")


@dataclass
@final
class KeyExt_t4(IdlStruct, typename="CdrStreamKeyExt::t4"):
    a: int32
    key("a")
    b: KeyExt_nested4


@dataclass
@appendable
class KeyExt_nested4a(IdlStruct, typename="CdrStreamKeyExt::nested4a"):
    a: int32
    key("a")


@dataclass
@final
class KeyExt_t4a(IdlStruct, typename="CdrStreamKeyExt::t4a"):
    a: int32
    key("a")
    b: KeyExt_nested4a
    key("b")


@dataclass
@appendable
class KeyExt_nested4b(IdlStruct, typename="CdrStreamKeyExt::nested4b"):
    a: int32


@dataclass
@final
class KeyExt_t4b(IdlStruct, typename="CdrStreamKeyExt::t4b"):
    a: int32
    key("a")
    b: KeyExt_nested4b
    key("b")


@dataclass
@mutable
class KeyExt_nested5(IdlStruct, typename="CdrStreamKeyExt::nested5"):
    a: int32
    key("a")


@dataclass
@final
class KeyExt_t5(IdlStruct, typename="CdrStreamKeyExt::t5"):
    a: int32
    key("a")
    b: KeyExt_nested5


@dataclass
@mutable
class KeyExt_nested5a(IdlStruct, typename="CdrStreamKeyExt::nested5a"):
    a: int32
    key("a")


@dataclass
@final
class KeyExt_t5a(IdlStruct, typename="CdrStreamKeyExt::t5a"):
    a: int32
    key("a")
    b: KeyExt_nested5a
    key("b")


@dataclass
@mutable
class KeyExt_nested5b(IdlStruct, typename="CdrStreamKeyExt::nested5b"):
    a: int32


@dataclass
@final
class KeyExt_t5b(IdlStruct, typename="CdrStreamKeyExt::t5b"):
    a: int32
    key("a")
    b: KeyExt_nested5b
    key("b")


@dataclass
@mutable
class KeyExt_nested6(IdlStruct, typename="CdrStreamKeyExt::nested6"):
    a: int32
    key("a")


@dataclass
@appendable
class KeyExt_t6(IdlStruct, typename="CdrStreamKeyExt::t6"):
    a: int32
    key("a")
    b: KeyExt_nested6


@dataclass
@mutable
class KeyExt_nested6a(IdlStruct, typename="CdrStreamKeyExt::nested6a"):
    a: int32
    key("a")


@dataclass
@appendable
class KeyExt_t6a(IdlStruct, typename="CdrStreamKeyExt::t6a"):
    a: int32
    key("a")
    b: KeyExt_nested6a
    key("b")


@dataclass
@mutable
class KeyExt_nested6b(IdlStruct, typename="CdrStreamKeyExt::nested6b"):
    a: int32


@dataclass
@appendable
class KeyExt_t6b(IdlStruct, typename="CdrStreamKeyExt::t6b"):
    a: int32
    key("a")
    b: KeyExt_nested6b
    key("b")


# ---------------------------------------------------------------- cyclonedds/src/tools/idlc/xtests

@bit_bound(10)
class e(IdlEnum, typename="e"):
    E1 = 0
    E2 = 1
    E3 = 2


@final
@nested
class u(IdlUnion, discriminator=int16, typename="u"):
    u1: case[1, e]
    ud: default[int32]


@dataclass
@final
class test_struct_keys(IdlStruct, typename="test_struct_keys"):
    f1: u
    f2: char
    key("f2")
    f3: u
    f4: array[char, 2]
    key("f4")


@dataclass
@mutable
@nested
class t_base_base(IdlStruct, typename="t_base_base"):
    bb1: int32
    key("bb1")


@dataclass
@mutable
@nested
class t_base(t_base_base, typename="t_base"):
    b1: int32


@dataclass
@mutable
class test_struct_inherit_mutable_keys(t_base, typename="test_struct_inherit_mutable_keys"):
    f1: int32


# -------------------------------------------------------- cyclonedds/src/core/ddsc/tests/CdrStreamSignedUnion.idl

@final
class SignedUnion_t1(IdlUnion, discriminator=int8, typename="CdrStreamSignedUnion::t1"):
    f1: case[-128, char]
    f2: case[-1, int16]
    f3: case[1, int32]
    f4: case[127, float32]


@final
class SignedUnion_t2(IdlUnion, discriminator=int16, typename="CdrStreamSignedUnion::t2"):
    f1: case[-32768, char]
    f2: case[-1, int16]
    f3: case[1, int32]
    f4: case[32767, float32]


@final
class SignedUnion_t3(IdlUnion, discriminator=int32, typename="CdrStreamSignedUnion::t3"):
    f1: case[-2147483648, char]
    f2: case[-1, int16]
    f3: case[1, int32]
    f4: case[2147483647, float32]


@dataclass
@final
class SignedUnion_t4(IdlStruct, typename="CdrStreamSignedUnion::t4"):
    f1: SignedUnion_t1
    f2: SignedUnion_t2
    f3: SignedUnion_t3


# ---------------------------------------------------------------- stand-ins: same wire form, other Python types
# Input for libddsc where the binding cannot encode the real value (see corpus_idl.via). Never topics themselves.

@dataclass
@appendable
class EnumWithValuesStructure_wire(IdlStruct, typename="EnumWithValuesStructure_wire"):
    var_enumwithvalues: int32  # a 4-byte enum holding -3


@final
@nested
class u_wire(IdlUnion, discriminator=int16, typename="u_wire"):
    u1: case[1, uint16]  # `e` has @bit_bound(10): 2 bytes in XCDR1 and XCDR2
    ud: default[int32]


@dataclass
@final
class test_struct_keys_wire(IdlStruct, typename="test_struct_keys_wire"):
    f1: u_wire
    f2: char
    f3: u_wire
    f4: array[char, 2]


# ---------------------------------------------------------------- rti-ros-data-types, compiled with final default
# The same ROS types as Cyclone's own idlc (and so rmw_cyclonedds) reads them: unannotated means @final there.
# The Rust side compiles these files a second time with `default_extensibility(Final)`.

@dataclass
@final
@nested
class std_msgs_msg_Time_F(IdlStruct, typename="std_msgs::msg::Time"):
    sec: int32
    nanosec: uint32


@dataclass
@final
class std_msgs_msg_Header_F(IdlStruct, typename="std_msgs::msg::Header"):
    stamp: std_msgs_msg_Time_F
    frame_id: str


@dataclass
@final
class geometry_msgs_msg_Point_F(IdlStruct, typename="geometry_msgs::msg::Point"):
    x: float64
    y: float64
    z: float64


@dataclass
@final
class geometry_msgs_msg_Quaternion_F(IdlStruct, typename="geometry_msgs::msg::Quaternion"):
    x: float64
    y: float64
    z: float64
    w: float64


@dataclass
@final
class geometry_msgs_msg_Vector3_F(IdlStruct, typename="geometry_msgs::msg::Vector3"):
    x: float64
    y: float64
    z: float64


@dataclass
@final
class geometry_msgs_msg_Pose_F(IdlStruct, typename="geometry_msgs::msg::Pose"):
    position: geometry_msgs_msg_Point_F
    orientation: geometry_msgs_msg_Quaternion_F


@dataclass
@final
class geometry_msgs_msg_PoseStamped_F(IdlStruct, typename="geometry_msgs::msg::PoseStamped"):
    header: std_msgs_msg_Header_F
    pose: geometry_msgs_msg_Pose_F


@dataclass
@final
class sensor_msgs_msg_Imu_F(IdlStruct, typename="sensor_msgs::msg::Imu"):
    header: std_msgs_msg_Header_F
    orientation: geometry_msgs_msg_Quaternion_F
    orientation_covariance: sensor_msgs_Imu_double_array_9
    angular_velocity: geometry_msgs_msg_Vector3_F
    angular_velocity_covariance: sensor_msgs_Imu_double_array_9
    linear_acceleration: geometry_msgs_msg_Vector3_F
    linear_acceleration_covariance: sensor_msgs_Imu_double_array_9


@dataclass
@final
class diagnostic_msgs_msg_KeyValue_F(IdlStruct, typename="diagnostic_msgs::msg::KeyValue"):
    key: str
    value: str


@dataclass
@final
class diagnostic_msgs_msg_DiagnosticStatus_F(IdlStruct, typename="diagnostic_msgs::msg::DiagnosticStatus"):
    level: byte
    name: str
    message: str
    hardware_id: str
    values: sequence[diagnostic_msgs_msg_KeyValue_F]
