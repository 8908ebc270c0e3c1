"""Writes tests/fixtures/golden/*.json from Cyclone DDS (see README.md there). Run through scripts/gen-golden."""

import enum
import hashlib
import json
import math
import os
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from cyclonedds.idl import IdlStruct, IdlUnion, IdlBitmask  # noqa: E402
from cyclonedds.idl._support import Endianness  # noqa: E402
from cyclonedds.idl._type_normalize import get_idl_annotations  # noqa: E402

import corpus  # noqa: E402
import rustgen  # noqa: E402
from oracle import Oracle  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
OUT = ROOT / "tests" / "fixtures" / "golden"
ORDERS = (("le", Endianness.Little), ("be", Endianness.Big))


def jvalue(v):
    """A readable, deterministic JSON form of a sample (documentation; the Rust side is generated code)."""
    if isinstance(v, IdlUnion):
        d, val = v.get()
        if d is None:
            d = type(v).__idl_default_discriminator__
        return {"discriminator": jvalue(d), "value": jvalue(val)}
    if isinstance(v, IdlBitmask):
        return {"mask": v.as_mask()}
    if isinstance(v, IdlStruct):
        return {k: jvalue(getattr(v, k)) for k in v.__dataclass_fields__}
    if isinstance(v, enum.Enum):
        return v.name
    if isinstance(v, (list, tuple, bytes, bytearray)):
        return [jvalue(x) for x in v]
    if isinstance(v, float):
        assert not math.isnan(v)
        return {"float": v.hex()} if (v == 0.0 and math.copysign(1, v) < 0) else v
    return v


def has_small_enum(t, seen=None):
    """Whether a type contains an enum with @bit_bound below 32 (the binding writes those as 4 bytes in XCDR1)."""
    from cyclonedds.idl._type_normalize import get_extended_type_hints, WrapOpt
    from cyclonedds.idl.types import sequence, array, typedef, case, default
    from inspect import isclass
    seen = seen if seen is not None else set()
    if id(t) in seen:
        return False
    seen.add(id(t))
    if isinstance(t, WrapOpt):
        return has_small_enum(t.inner, seen)
    if isinstance(t, (sequence, array, typedef, case, default)):
        return has_small_enum(t.subtype, seen)
    if isclass(t) and issubclass(t, enum.Enum):
        return get_idl_annotations(t).get("bit_bound", 32) < 32
    if isclass(t) and issubclass(t, IdlUnion):
        return has_small_enum(t.__idl_discriminator__, seen) or any(
            has_small_enum(x, seen) for x in get_extended_type_hints(t).values())
    if isclass(t) and issubclass(t, IdlStruct):
        return any(has_small_enum(x, seen) for x in get_extended_type_hints(t).values())
    return False


def be_from_le(le_payload, be_body):
    """Big-endian payload: the C core's BE body under the C core's LE header with the endianness bit cleared."""
    pad = le_payload[3] & 3
    le_body = le_payload[4:len(le_payload) - pad]
    if len(le_body) != len(be_body):
        raise RuntimeError(f"C core LE/BE body lengths differ: {len(le_body)} vs {len(be_body)}")
    return bytes([le_payload[0], le_payload[1] & ~1, le_payload[2], le_payload[3]]) + be_body + bytes(pad)


def norm_text(text):
    """libddsc's sample print without its encoding-specific decorations (DHEADER sizes, EMHEADERs, braces)."""
    import re
    return re.sub(r"<\d+>|pl:\d+,|lc:\d+,m:\d+,|[{},]", "", text)


def strip_padding(payload):
    pad = payload[3] & 3
    return payload[:2] + b"\0\0" + payload[4:len(payload) - pad]


class TypeRun:
    """Builds one type's fixture document: libddsc's vectors for every sample, plus the cross-checks."""

    def __init__(self, oracle, cls, problems):
        self.cls, self.problems = cls, problems
        self.idl = cls.__idl__
        self.idl.populate()
        self.ct = oracle.ctype(cls)
        self.keyed = self.ct.nkeys > 0  # libddsc's view; the binding calls every union keyed
        self.refused_write, self.bad_be, self.default_versions = set(), set(), set()
        self.doc = {
            "type": cls.__name__,
            "typename": self.idl.idl_transformed_typename,
            "extensibility": get_idl_annotations(cls).get("extensibility", "final"),
            "keyed": self.keyed,
            "python_default_version": self.idl.default_version,
            "member_ids": dict(self.idl.member_ids),
            "refused": [f"XCDR{v}: {why}" for v, why in sorted(self.ct.refused.items())],
            "samples": [],
        }

    def problem(self, name, what):
        self.problems.append(f"{self.cls.__name__}/{name}: {what}")

    def sample(self, name, sample):
        s = {"name": name, "value": jvalue(sample), "data": {}, "python": {}, "notes": []}
        if self.keyed:
            s.update({"key": {}, "key_hash": {}, "python_key": {}})
        py = {}
        for ver in (1, 2):
            for o, e in ORDERS:
                py[(ver, o)] = sample.serialize(use_version_2=(ver == 2), endianness=e)
                s["python"][f"xcdr{ver}_{o}"] = py[(ver, o)].hex()
        # One C sample per value, read from the binding's little-endian bytes (XCDR2 preferred). Big-endian
        # input is never fed to libddsc 11.0.1: it misreads and then crashes on BE XCDR1 optionals.
        reads = {}
        for ver in (2, 1):
            mem, text = self.ct.read(py[(ver, "le")])
            if mem is None:
                s["notes"].append(f"xcdr{ver}_le: the C core rejects the binding's bytes")
            else:
                reads[ver] = (mem, text)
        s["c_accepts"] = [f"xcdr{v}_le" for v in sorted(reads)]
        if not reads:
            self.problem(name, "the C core rejects every encoding the binding produces")
        else:
            dv = self.ct.default_version((reads.get(2) or reads[1])[0])
            if dv is not None:
                self.default_versions.add(dv)
            for ver in (1, 2):
                self.version(s, name, sample, ver, py, reads)
        s["decode_also"] = self.decode_also(s, py, reads)
        self.doc["samples"].append(s)

    def version(self, s, name, sample, ver, py, reads):
        tag = f"xcdr{ver}"
        if ver not in self.ct.sertype:
            s["notes"].append(f"{tag}: C core refuses this representation for the type")
            return
        mem, text = reads.get(2) or reads[1]
        try:
            sd, c_le = self.ct.write(mem, ver)
        except Exception:
            s["notes"].append(f"{tag}: the C core refuses to write this sample as XCDR{ver}")
            self.refused_write.add(ver)
            return
        if ver in reads and reads[ver][1] != text:
            s["notes"].append(f"{tag}: the C core reads the binding's XCDR{ver} bytes as {reads[ver][1]}, "
                              f"not {text}")
        s["data"][f"{tag}_le"] = c_le.hex()
        s["c_text"] = text
        c_be = self.big_endian(s, tag, mem, ver, c_le, py[(ver, "be")])
        self.compare_binding(s, tag, {"le": c_le, "be": c_be}, {o: py[(ver, o)] for o, _ in ORDERS})
        if self.keyed:
            self.key(s, name, sample, ver, mem, sd, c_le, py[(ver, "le")])

    def big_endian(self, s, tag, mem, ver, c_le, py_be):
        """libddsc's BE payload, kept only if it survives two witnesses (see README.md)."""
        c_be = be_from_le(c_le, self.ct.write_be_body(mem, ver))
        # libddsc's reader must decode its BE bytes to the same sample. It shares some BE bugs with its writer
        # (union default members), so the binding's BE bytes are the second witness, except where the binding
        # is known to deviate (XCDR1 enums with a bit_bound: it always writes 4 bytes).
        self_ok = self.ct.reencode_isolated(c_be, ver) == c_le
        agree = strip_padding(py_be) == strip_padding(c_be)
        py_deviates = ver == 1 and has_small_enum(self.cls)
        if self_ok and (agree or py_deviates):
            s["data"][f"{tag}_be"] = c_be.hex()
        else:
            s["notes"].append(f"{tag}_be: no vector: the C core's BE writer gives {c_be.hex()}, which "
                              + ("the binding's BE bytes contradict" if self_ok else "its own reader rejects"))
            self.bad_be.add(ver)
        return c_be

    def compare_binding(self, s, tag, c, py):
        for o in ("le", "be"):
            if py[o] == c[o]:
                continue
            if strip_padding(py[o]) == strip_padding(c[o]):
                s["notes"].append(f"{tag}_{o}: binding omits the end padding the C core adds (options "
                                  f"{c[o][2:4].hex()}); otherwise identical")
            else:
                s["notes"].append(f"{tag}_{o}: binding bytes differ from the C core's; fixture uses the C core's")
        for o in ("le", "be"):
            try:
                if jvalue(self.cls.deserialize(c[o])) != s["value"]:
                    s["notes"].append(f"{tag}_{o}: binding decodes the C core's bytes to a different value")
            except Exception as exc:  # the binding's decoder is not the authority; record only
                s["notes"].append(f"{tag}_{o}: binding cannot decode the C core's bytes ({type(exc).__name__})")

    def key(self, s, name, sample, ver, mem, sd, c_le, py_le):
        tag = f"xcdr{ver}"
        k_le = self.ct.write_key(mem, ver)
        k_be = be_from_le(k_le, self.ct.key_be_body(c_le[4:len(c_le) - (c_le[3] & 3)], ver))
        s["key"][f"{tag}_le"] = k_le.hex()
        s["key"][f"{tag}_be"] = k_be.hex()
        kh = self.ct.keyhash(sd)
        s["key_hash"][tag] = kh.hex()
        # What libddsc hashes (diagnosis aid): zero-padded to 16 bytes, or its MD5.
        k2 = self.ct.write_key(mem, 2)
        stream = self.ct.keyhash_stream(k2[4:len(k2) - (k2[3] & 3)], ver)
        s.setdefault("key_hash_stream", {})[tag] = stream.hex()
        padded = stream.ljust(16, b"\0") if len(stream) <= 16 else b""
        if kh not in (padded, hashlib.md5(stream).digest()):
            self.problem(name, f"{tag}: key hash is neither the padded stream nor its MD5")
        pkh = self.ct.py_keyhash(py_le)
        if pkh is not None and pkh != kh:
            s["notes"].append(f"{tag}: the binding's sertype computes key hash {pkh.hex()}, the C core "
                              f"{kh.hex()}; fixture uses the C core's")
        for o, e in ORDERS:
            pk = self.idl.serialize_key(sample, use_version_2=(ver == 2), endianness=e)
            s["python_key"][f"{tag}_{o}"] = pk.hex()
            if strip_padding(k_le if o == "le" else k_be)[4:] != pk:
                s["notes"].append(f"{tag}_{o}: binding's serialize_key differs from the C core's key")

    @staticmethod
    def decode_also(s, py, reads):
        """Other byte strings libddsc accepts for this value: the binding's, when they differ from the C core's
        only by end padding, or when the C core reads but will not write that version. Decode-only checks."""
        out = {}
        if not reads:
            return out
        ref_text = norm_text((reads.get(2) or reads[1])[1])
        for ver in sorted(reads):
            tag = f"xcdr{ver}_le"
            pyb = py[(ver, "le")]
            canon = s["data"].get(tag)
            if canon is not None:
                canon = bytes.fromhex(canon)
                if pyb != canon and strip_padding(pyb) == strip_padding(canon):
                    out[f"python_{tag}"] = pyb.hex()
            elif norm_text(reads[ver][1]) == ref_text:
                out[f"python_{tag}"] = pyb.hex()
        return out

    def finish(self):
        doc = self.doc
        for ver in sorted(self.refused_write):
            doc["refused"].append(f"XCDR{ver}: the C core reads the binding's XCDR{ver} bytes but will not write "
                                  f"XCDR{ver} for this type (non-mutable type with @optional members)")
        if len(self.default_versions) == 1:
            doc["libddsc_default_version"] = next(iter(self.default_versions))
        elif self.default_versions:
            self.problem("*", "libddsc's default version differs between samples")
        for ver in sorted(self.bad_be):
            doc["refused"].append(f"XCDR{ver} BE for some samples: the C core's BE writer output is contradicted "
                                  "by the binding or by its own reader (see the sample notes)")
        return doc


def one_type(oracle, cls, samples, problems):
    run = TypeRun(oracle, cls, problems)
    for name, sample in samples:
        run.sample(name, sample)
    return run.finish()


def main():
    OUT.mkdir(parents=True, exist_ok=True)
    oracle = Oracle()
    problems = []
    manifest = {"generator": "scripts/gen-golden", "peer": "cyclonedds (Python binding + libddsc) 11.0.1",
                "types": []}
    written = set()
    for cls, samples in corpus.CORPUS:
        doc = one_type(oracle, cls, samples, problems)
        fname = f"{cls.__name__}.json"
        (OUT / fname).write_text(json.dumps(doc, indent=1, sort_keys=False, ensure_ascii=False) + "\n")
        written.add(fname)
        manifest["types"].append({
            "type": doc["type"], "file": fname, "typename": doc["typename"], "keyed": doc["keyed"],
            "extensibility": doc["extensibility"], "samples": [s["name"] for s in doc["samples"]],
            "encodings": sorted({k for s in doc["samples"] for k in s["data"]}),
            "refused": doc["refused"],
        })
    manifest["probes"] = []
    for cls, what, sample in corpus.PROBES:
        ver = 1 if "XCDR1" in what else 2
        data = sample.serialize(use_version_2=(ver == 2), endianness=Endianness.Little)
        mem, text = oracle.ctype(cls).read(data)
        manifest["probes"].append({"type": cls.__name__, "what": what, "bytes": data.hex(),
                                   "accepted_by_libddsc": mem is not None, "libddsc_reads": text})
    manifest["problems"] = problems
    (OUT / "manifest.json").write_text(json.dumps(manifest, indent=1, ensure_ascii=False) + "\n")
    written.add("manifest.json")
    for stale in OUT.glob("*.json"):
        if stale.name not in written:
            stale.unlink()
    rustgen.write(ROOT / "tests" / "tests" / "golden" / "types.rs", corpus.CORPUS)
    nfix = sum(len(t["samples"]) * len(t["encodings"]) for t in manifest["types"])
    print(f"gen-golden: {len(manifest['types'])} types, {nfix} sample encodings; {len(problems)} problems")
    for p in problems:
        print("  problem:", p)
    sys.stdout.flush()
    os._exit(1 if problems else 0)  # skip interpreter teardown: the C core holds buffers we lent it


if __name__ == "__main__":
    main()
