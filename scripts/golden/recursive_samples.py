"""Writes tests/fixtures/samples-recursive/samples.json: values of the recursive types of rec_golden/ as Cyclone
DDS 11.0.1's Python binding serializes them (its own serializer, with encapsulation header), in XCDR1 and XCDR2,
little and big endian, next to each value as JSON. The decoders of the derive and of dynamic types must read
these bytes back to the same values. Run through scripts/gen-golden.
"""

import dataclasses
import json
import sys
from pathlib import Path

from cyclonedds.idl._support import Endianness

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import rec_golden as r  # noqa: E402

OUT = HERE.parents[1] / "tests" / "fixtures" / "samples-recursive" / "samples.json"


def values():
    leaf = lambda v: r.Node(value=v, children=[])  # noqa: E731
    node = r.Node(value=1, children=[leaf(2), r.Node(value=3, children=[leaf(4)])])
    a = r.A(x=1, bs=[r.B(y=2, as_=[r.A(x=3, bs=[])]), r.B(y=4, as_=[])])
    tree = r.Tree(v=1, leaf=r.Leaf(name="root"),
                  kids=[r.Tree(v=2, leaf=r.Leaf(name="k"), kids=[]),
                        r.Tree(v=3, leaf=r.Leaf(name=""), kids=[r.Tree(v=4, leaf=r.Leaf(name="x"), kids=[])])])
    holder = r.Holder(id=7, root=node, a=a)
    chain = r.Chain(v=1, next=r.Chain(v=2, next=r.Chain(v=3, next=None)))
    return [("Node", node), ("A", a), ("Tree", tree), ("Holder", holder), ("Chain", chain)]


def plain(v):
    """The value as JSON, as our DynamicData's JSON form has it (absent optional members null)."""
    if dataclasses.is_dataclass(v):
        return {f.name: plain(getattr(v, f.name)) for f in dataclasses.fields(v)}
    if isinstance(v, list):
        return [plain(x) for x in v]
    return v


def main():
    out = []
    for name, v in values():
        enc = {}
        for version, v2 in (("xcdr1", False), ("xcdr2", True)):
            for order, e in (("le", Endianness.Little), ("be", Endianness.Big)):
                enc[f"{version}_{order}"] = v.serialize(endianness=e, use_version_2=v2).hex()
        out.append({"type": name, "typename": v.__idl__.idl_transformed_typename, "json": plain(v), "bytes": enc})
    OUT.parent.mkdir(parents=True, exist_ok=True)
    doc = {"peer": "cyclonedds (Python binding) 11.0.1, IdlStruct.serialize", "samples": out}
    OUT.write_text(json.dumps(doc, indent=1) + "\n")
    print(f"gen-golden (recursive samples): {len(out)} values")


if __name__ == "__main__":
    main()
