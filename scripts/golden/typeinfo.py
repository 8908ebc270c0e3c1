"""Writes tests/fixtures/typeinfo/*.json: Cyclone's XCDR2 TypeInformation and TypeMapping bytes for every type of
the CDR golden corpus (corpus.py) and the idlc golden corpus (corpus_idl.py), as the Python binding of Cyclone DDS
11.0.1 builds them (`__idl__.fill_type_data()`, the bytes it hands to libddsc when it creates a topic). Run through
scripts/gen-golden. Our own encoder is never consulted.
"""

import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

import corpus  # noqa: E402
import corpus_idl  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
OUT = ROOT / "tests" / "fixtures" / "typeinfo"


def doc_of(cls, fixture):
    idl = cls.__idl__
    idl.populate()
    idl.fill_type_data()
    info, mapping = idl._xt_bytedata
    ti = idl.get_type_info()
    return {
        "fixture": fixture,
        "typename": idl.idl_transformed_typename,
        "peer": "cyclonedds (Python binding) 11.0.1, __idl__ TypeInformation/TypeMapping, XCDR2 LE, no header",
        "minimal_typeid_size": ti.minimal.typeid_with_size.typeobject_serialized_size,
        "complete_typeid_size": ti.complete.typeid_with_size.typeobject_serialized_size,
        "minimal_dependent_count": ti.minimal.dependent_typeid_count,
        "complete_dependent_count": ti.complete.dependent_typeid_count,
        "type_information": info.hex(),
        "type_mapping": mapping.hex(),
    }


def main():
    OUT.mkdir(parents=True, exist_ok=True)
    written = set()
    entries = [(cls.__name__, cls) for cls, _ in corpus.CORPUS]
    entries += [(f"idlc.{fixture}", cls) for fixture, _, _, cls, _ in corpus_idl.ENTRIES]
    for name, cls in entries:
        fname = f"{name}.json"
        (OUT / fname).write_text(json.dumps(doc_of(cls, name), indent=1) + "\n")
        written.add(fname)
    for stale in OUT.glob("*.json"):
        if stale.name not in written:
            stale.unlink()
    print(f"gen-golden (typeinfo): {len(written)} types")


if __name__ == "__main__":
    main()
