"""Writes tests/fixtures/typeobject-bitset/bitsets.json: TK_BITSET type objects (CompleteBitsetType and
MinimalBitsetType, XTypes 1.3 7.3.4.x) serialized by Cyclone DDS 11.0.1's Python binding, with its own
definitions of the type-object IDL (cyclonedds.idl._typesupport.DDS.XTypes). No peer makes these objects from
IDL (Cyclone's idlc rejects `bitset`, fastddsgen 2.3.0 fails on it), so the objects are written by hand here,
and only the binding's codec is the reference: the layout of each struct (final, appendable, DHEADERs).
Run through scripts/gen-golden.
"""

import json
from pathlib import Path

from cyclonedds.idl._support import Endianness
import cyclonedds.idl._typesupport.DDS.XTypes as xt

OUT = Path(__file__).resolve().parents[2] / "tests" / "fixtures" / "typeobject-bitset"

# (name, bitcount, holder kind), positions in order.
FIELDS = [("ready", 1, xt.TK_BOOLEAN), ("mode", 3, xt.TK_UINT8), ("count", 12, xt.TK_UINT16)]


def fields():
    pos = 0
    for name, bits, holder in FIELDS:
        yield pos, name, bits, holder
        pos += bits


def common(pos, bits, holder):
    return xt.CommonBitfield(position=pos, flags=xt.MemberFlag(), bitcount=bits, holder_type=holder)


def complete():
    return xt.TypeObject(complete=xt.CompleteTypeObject(bitset_type=xt.CompleteBitsetType(
        bitset_flags=xt.TypeFlag(),
        header=xt.CompleteBitsetHeader(detail=xt.CompleteTypeDetail(
            ann_builtin=None, ann_custom=None, type_name="Bits::Flags")),
        field_seq=[
            xt.CompleteBitfield(common=common(p, b, h), detail=xt.CompleteMemberDetail(
                name=n, ann_builtin=None, ann_custom=None))
            for p, n, b, h in fields()
        ])))


def minimal():
    from hashlib import md5
    return xt.TypeObject(minimal=xt.MinimalTypeObject(bitset_type=xt.MinimalBitsetType(
        bitset_flags=xt.TypeFlag(),
        header=xt.MinimalBitsetHeader(),
        field_seq=[
            xt.MinimalBitfield(common=common(p, b, h), name_hash=md5(n.encode()).digest()[:4])
            for p, n, b, h in fields()
        ])))


def main():
    OUT.mkdir(parents=True, exist_ok=True)
    doc = {
        "peer": "cyclonedds (Python binding) 11.0.1, DDS.XTypes.TypeObject.serialize, XCDR2 LE, no header",
        "idl": "bitset Bits::Flags { bitfield<1, boolean> ready; bitfield<3, uint8> mode; "
               "bitfield<12, unsigned short> count; };",
        "fields": [[p, n, b, h] for p, n, b, h in fields()],
        "complete": complete().serialize(endianness=Endianness.Little, use_version_2=True)[4:].hex(),
        "minimal": minimal().serialize(endianness=Endianness.Little, use_version_2=True)[4:].hex(),
    }
    (OUT / "bitsets.json").write_text(json.dumps(doc, indent=1) + "\n")
    print("gen-golden (bitset type objects): 2 objects")


if __name__ == "__main__":
    main()
