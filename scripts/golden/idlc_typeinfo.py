"""Writes tests/fixtures/cyclone-idlc/<stem>.json for every tests/idl/<stem>.idl: the XCDR2
TypeInformation and TypeMapping bytes that Cyclone DDS 11.0.1's own idlc puts in its C output (TYPE_INFO_CDR_*,
TYPE_MAP_CDR_*) for each type (the IDL gives every type its extensibility: the compilers' defaults differ). Run through
scripts/gen-golden; needs ../shared/cyclonedds-11.0.1 (or $CYCLONEDDS_HOME). Our encoder is never consulted.
"""

import json
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
OUT = ROOT / "tests" / "fixtures" / "cyclone-idlc"
CYCLONE = Path(os.environ.get("CYCLONEDDS_HOME", ROOT.parent / "shared" / "cyclonedds-11.0.1"))
ARRAY = re.compile(r"#define TYPE_(INFO|MAP)_CDR_(\w+) \(const unsigned char \[\]\)\{ \\\n(.*?)\n\}", re.S)


def lib_dir(tmp):
    """Cyclone's lib/ may hold its .so symlinks as small text files: a directory of real symlinks instead."""
    src, dst = CYCLONE / "lib", Path(tmp) / "lib"
    dst.mkdir()
    for f in src.glob("*.so*"):
        target = f.name
        while (src / target).stat().st_size < 100:
            target = (src / target).read_text().strip()
        (dst / f.name).symlink_to(src / target)
    return dst


def c_names(idl_text):
    """C name (`M_S`) -> scoped IDL name (`M::S`) of every struct and union, by module nesting."""
    names, stack = {}, []
    for tok in re.finditer(r"\bmodule\s+(\w+)\s*\{|\b(?:struct|union)\s+(\w+)\b[^;{]*\{|(\{)|(\})", idl_text):
        mod, ty, opening, closing = tok.groups()
        if mod:
            stack.append(mod)
        elif ty:
            names["_".join(stack + [ty])] = "::".join(stack + [ty])
            stack.append(None)
        elif opening:
            stack.append(None)
        elif closing and stack:
            stack.pop()
    return names


def one(idl, tmp, libs):
    env = dict(os.environ, LD_LIBRARY_PATH=str(libs))
    subprocess.run([str(CYCLONE / "bin" / "idlc"), "-o", tmp, str(idl)], check=True, env=env)
    text = (Path(tmp) / f"{idl.stem}.c").read_text()
    names = c_names(re.sub(r"//.*", "", idl.read_text()))
    types = {}
    for kind, cname, body in ARRAY.findall(text):
        data = bytes(int(b, 16) for b in re.findall(r"0x([0-9a-f]{2})", body))
        key = "type_information" if kind == "INFO" else "type_mapping"
        types.setdefault(names.get(cname, cname), {})[key] = data.hex()
    return {
        "peer": "Cyclone DDS 11.0.1 idlc (C generator): TYPE_INFO_CDR_*/TYPE_MAP_CDR_*, XCDR2 LE",
        "idl": str(idl.relative_to(ROOT)),
        "types": dict(sorted(types.items())),
    }


def main():
    OUT.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        libs = lib_dir(tmp)
        for idl in sorted((ROOT / "tests" / "idl").glob("*.idl")):
            doc = one(idl, tmp, libs)
            path = OUT / f"{idl.stem}.json"
            path.write_text(json.dumps(doc, indent=1) + "\n")
            print(f"{path.relative_to(ROOT)}: {len(doc['types'])} types", file=sys.stderr)


if __name__ == "__main__":
    main()
