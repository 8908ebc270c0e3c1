"""Writes tests/fixtures/typeinfo-recursive/*.json: the TypeInformation and TypeMapping bytes Cyclone DDS 11.0.1's
Python binding computes for recursive types (rec_golden/), with their strongly connected component identifiers
(XTypes 1.3 7.3.4.9). libddsc 11 refuses these objects at topic creation and Cyclone's idlc does not finish on
such IDL, so the binding's builder is the only peer reference. Run through scripts/gen-golden.

Each type is computed in a process of its own: within one process the binding caches what it built for earlier
topic types and mutates the identifiers it handed out, so a type computed after another of its component gets
other hashes (B after A: a different SCC hash than B alone, or A alone). Alone, every type of a component gives
the same hash, as XTypes 1.3 7.3.4.9 means it to.
"""

import json
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import rec_golden  # noqa: E402

OUT = HERE.parents[1] / "tests" / "fixtures" / "typeinfo-recursive"
TYPES = ["Node", "A", "B", "Tree", "Holder", "Chain"]


def doc_of(name):
    cls = getattr(rec_golden, name)
    idl = cls.__idl__
    idl.populate()
    idl.fill_type_data()
    info, mapping = idl._xt_bytedata
    return {
        "fixture": name,
        "typename": idl.idl_transformed_typename,
        "idl": cls.__doc__,
        "peer": "cyclonedds (Python binding) 11.0.1, __idl__ TypeInformation/TypeMapping, XCDR2 LE, no header",
        "type_information": info.hex(),
        "type_mapping": mapping.hex(),
    }


def main():
    if len(sys.argv) == 2:
        print(json.dumps(doc_of(sys.argv[1]), indent=1))
        return
    OUT.mkdir(parents=True, exist_ok=True)
    for name in TYPES:
        doc = subprocess.run([sys.executable, __file__, name], check=True, capture_output=True, text=True).stdout
        (OUT / f"{name}.json").write_text(doc)
    print(f"gen-golden (recursive typeinfo): {len(TYPES)} types, one process each")


if __name__ == "__main__":
    main()
