"""Cyclone DDS's C core (libddsc 11.0.1, shipped inside the cyclonedds wheel) driven through ctypes.

The Python binding has its own serializer, written in Python. The bytes a Cyclone C application puts on the
wire come from libddsc's cdrstream code instead, so every Python-built sample is pushed through the C core:

  python bytes --ddsi_serdata_from_ser_iov (normalize: validates)--> --ddsi_serdata_to_sample--> C sample
  C sample --ddsi_serdata_from_sample + ddsi_serdata_to_ser--> the C core's own encoding (native = little endian)
  C sample --dds_stream_write_sampleBE--> the C core's big-endian body
  serdata --ddsi_serdata_get_keyhash--> the 16-byte key hash Cyclone puts in PID_KEY_HASH

The C-typed topics are created from the TypeInformation the binding registers (dds_create_topic_descriptor), so
the C core works from the same type the binding describes on the wire.
"""

import ctypes as ct

from cyclonedds.__library__ import library_path
from cyclonedds.domain import DomainParticipant
from cyclonedds.topic import Topic

vp = ct.c_void_p
SDK_KEY, SDK_DATA = 1, 2
DDS_FIND_SCOPE_LOCAL_DOMAIN = 1
XCDR1_REPR, XCDR2_REPR = 0, 2


class Iovec(ct.Structure):
    _fields_ = [("base", vp), ("len", ct.c_size_t)]


class Stream(ct.Structure):  # dds_istream_t / dds_ostream_t / dds_ostreamBE_t share this layout
    _fields_ = [("buf", vp), ("size", ct.c_uint32), ("index", ct.c_uint32), ("xcdr_version", ct.c_uint32)]


def _load():
    lib = ct.CDLL(str(library_path))
    sigs = {
        "dds_get_entity_sertype": ([ct.c_int32, ct.POINTER(vp)], ct.c_int32),
        "dds_get_typeinfo": ([ct.c_int32, ct.POINTER(vp)], ct.c_int32),
        "dds_create_topic_descriptor": ([ct.c_int, ct.c_int32, vp, ct.c_int64, ct.POINTER(vp)], ct.c_int32),
        "dds_create_topic": ([ct.c_int32, vp, ct.c_char_p, vp, vp], ct.c_int32),
        "dds_create_qos": ([], vp),
        "dds_delete_qos": ([vp], None),
        "dds_qset_data_representation": ([vp, ct.c_uint32, ct.POINTER(ct.c_int16)], None),
        "ddsi_serdata_from_ser_iov": ([vp, ct.c_int, ct.c_size_t, ct.POINTER(Iovec), ct.c_size_t], vp),
        "ddsi_serdata_from_sample": ([vp, ct.c_int, vp], vp),
        "ddsi_serdata_to_sample": ([vp, vp, vp, vp], ct.c_bool),
        "ddsi_serdata_size": ([vp], ct.c_uint32),
        "ddsi_serdata_to_ser": ([vp, ct.c_size_t, ct.c_size_t, vp], None),
        "ddsi_serdata_get_keyhash": ([vp, ct.c_char_p, ct.c_bool], None),
        "ddsi_serdata_print": ([vp, ct.c_char_p, ct.c_size_t], ct.c_size_t),
        "ddsi_serdata_unref": ([vp], None),
        "dds_cdrstream_desc_from_topic_desc": ([vp, vp], None),
        "dds_ostreamBE_init": ([ct.POINTER(Stream), vp, ct.c_uint32, ct.c_uint32], None),
        "dds_ostreamBE_fini": ([ct.POINTER(Stream), vp], None),
        "dds_stream_write_sampleBE": ([ct.POINTER(Stream), vp, vp, vp], ct.c_bool),
        "dds_stream_extract_keyBE_from_data": ([ct.POINTER(Stream), ct.POINTER(Stream), vp, vp], ct.c_bool),
        "dds_stream_extract_keyBE_from_key": ([ct.POINTER(Stream), ct.POINTER(Stream), ct.c_int, vp, vp], None),
    }
    for name, (args, res) in sigs.items():
        f = getattr(lib, name)
        f.argtypes, f.restype = args, res
    return lib


class OracleError(Exception):
    pass


class CType:
    """One IDL type known to the C core: a Python-binding topic plus C-typed topics for XCDR1 and XCDR2."""

    def __init__(self, oracle, cls, index):
        self.o, self.cls = oracle, cls
        lib = oracle.lib
        self.pytopic = Topic(oracle.dp, f"golden_py_{index}", cls)
        ti = vp()
        if lib.dds_get_typeinfo(self.pytopic._ref, ct.byref(ti)) != 0:
            raise OracleError("dds_get_typeinfo failed")
        self.desc = vp()
        rc = lib.dds_create_topic_descriptor(DDS_FIND_SCOPE_LOCAL_DOMAIN, oracle.dp._ref, ti, 0, ct.byref(self.desc))
        if rc != 0:
            raise OracleError(f"dds_create_topic_descriptor: {rc}")
        head = ct.cast(self.desc, ct.POINTER(ct.c_uint32))  # dds_topic_descriptor_t: m_size, m_align, m_flagset, m_nkeys
        self.sample_size = head[0]
        self.nkeys = head[3]
        self.cdrdesc = ct.create_string_buffer(512)  # struct dds_cdrstream_desc is far smaller
        lib.dds_cdrstream_desc_from_topic_desc(self.cdrdesc, self.desc)
        self.pysertype = self._sertype(self.pytopic._ref)
        self.sertype = {}
        self.refused = {}
        for ver, rep in ((1, XCDR1_REPR), (2, XCDR2_REPR)):
            qos = lib.dds_create_qos()
            lib.dds_qset_data_representation(qos, 1, (ct.c_int16 * 1)(rep))
            tp = lib.dds_create_topic(oracle.dp._ref, self.desc, f"golden_c{ver}_{index}".encode(), qos, None)
            lib.dds_delete_qos(qos)
            if tp < 0:
                why = "DDS_RETCODE_BAD_PARAMETER" if tp == -3 else str(tp)
                self.refused[ver] = f"libddsc will not create a topic for this type with data representation " \
                                    f"XCDR{ver} ({why})"
            else:
                self.sertype[ver] = self._sertype(tp)

    def default_version(self, mem):
        """XCDR version libddsc writes for this type when the topic QoS names no data representation."""
        lib = self.o.lib
        if not hasattr(self, "_default_st"):
            self.o.n += 1
            tp = lib.dds_create_topic(self.o.dp._ref, self.desc, f"golden_cdef_{self.o.n}".encode(), None, None)
            self._default_st = self._sertype(tp) if tp >= 0 else None
        if self._default_st is None:
            return None
        sd = lib.ddsi_serdata_from_sample(self._default_st, SDK_DATA, mem)
        if not sd:
            return None
        return 2 if self._to_ser(sd)[1] > 3 else 1

    def _sertype(self, entity):
        st = vp()
        if self.o.lib.dds_get_entity_sertype(entity, ct.byref(st)) != 0:
            raise OracleError("dds_get_entity_sertype failed")
        return st

    def _from_ser(self, sertype, data, kind=SDK_DATA):
        buf = ct.create_string_buffer(bytes(data), len(data))
        self.o.keep.append(buf)
        iov = Iovec(ct.cast(buf, vp), len(data))
        return self.o.lib.ddsi_serdata_from_ser_iov(sertype, kind, 1, ct.byref(iov), len(data))

    def _to_ser(self, sd):
        n = self.o.lib.ddsi_serdata_size(sd)
        b = ct.create_string_buffer(n)
        self.o.lib.ddsi_serdata_to_ser(sd, 0, n, b)
        return b.raw

    def read(self, data):
        """Python-encoded bytes -> C sample memory (None when the C core rejects the bytes)."""
        ver = 2 if data[1] > 3 else 1
        st = self.sertype.get(ver) or next(iter(self.sertype.values()))
        sd = self._from_ser(st, data)
        if not sd:
            return None, None
        text = ct.create_string_buffer(4096)
        self.o.lib.ddsi_serdata_print(sd, text, 4096)
        mem = ct.create_string_buffer(max(self.sample_size, 8))
        self.o.keep.append(mem)
        if not self.o.lib.ddsi_serdata_to_sample(sd, mem, None, None):
            return None, None
        return mem, text.value.decode("utf-8", "replace")

    def write(self, mem, ver):
        """C sample -> the C core's encoding (little endian, header included)."""
        sd = self.o.lib.ddsi_serdata_from_sample(self.sertype[ver], SDK_DATA, mem)
        if not sd:
            raise OracleError("ddsi_serdata_from_sample(data) failed")
        return sd, self._to_ser(sd)

    def write_key(self, mem, ver):
        sd = self.o.lib.ddsi_serdata_from_sample(self.sertype[ver], SDK_KEY, mem)
        if not sd:
            raise OracleError("ddsi_serdata_from_sample(key) failed")
        return self._to_ser(sd)

    def write_be_body(self, mem, ver):
        """C sample -> the C core's big-endian body (no header, no end padding)."""
        lib = self.o.lib
        os_ = Stream()
        alloc = ct.cast(lib.dds_cdrstream_default_allocator, vp)
        lib.dds_ostreamBE_init(ct.byref(os_), alloc, 0, ver)
        if not lib.dds_stream_write_sampleBE(ct.byref(os_), alloc, mem, self.cdrdesc):
            raise OracleError("dds_stream_write_sampleBE failed")
        out = ct.string_at(os_.buf, os_.index)
        lib.dds_ostreamBE_fini(ct.byref(os_), alloc)
        return out

    def key_be_body(self, le_body, ver):
        """Key extracted by the C core from its own little-endian data, written big-endian."""
        lib = self.o.lib
        buf = ct.create_string_buffer(le_body, len(le_body))
        is_ = Stream(ct.cast(buf, vp), len(le_body), 0, ver)
        os_ = Stream()
        alloc = ct.cast(lib.dds_cdrstream_default_allocator, vp)
        lib.dds_ostreamBE_init(ct.byref(os_), alloc, 0, ver)
        if not lib.dds_stream_extract_keyBE_from_data(ct.byref(is_), ct.byref(os_), alloc, self.cdrdesc):
            raise OracleError("dds_stream_extract_keyBE_from_data failed")
        out = ct.string_at(os_.buf, os_.index)
        lib.dds_ostreamBE_fini(ct.byref(os_), alloc)
        return out

    def reencode_isolated(self, data, ver, timeout=10):
        """Reads `data` with the C core in a forked child and returns its re-encoding as XCDR`ver` LE.

        Forked because libddsc 11.0.1 crashes on some big-endian inputs; None when the child fails."""
        import os
        import signal
        r, w = os.pipe()
        pid = os.fork()
        if pid == 0:
            os.close(r)
            signal.alarm(timeout)
            try:
                mem, _ = self.read(data)
                out = b"" if mem is None else self.write(mem, ver)[1]
                os.write(w, out)
            finally:
                os._exit(0)
        os.close(w)
        chunks = []
        while True:
            b = os.read(r, 65536)
            if not b:
                break
            chunks.append(b)
        os.close(r)
        _, status = os.waitpid(pid, 0)
        out = b"".join(chunks)
        if status != 0 or not out:
            return None
        return out

    def keyhash_stream(self, key2_le_body, ver):
        """The big-endian stream libddsc hashes for a payload of version `ver` (KEYHASH serialization kind),
        from the XCDR2 little-endian key-only body, as the binding's sertype does it."""
        lib = self.o.lib
        buf = ct.create_string_buffer(key2_le_body, len(key2_le_body))
        is_ = Stream(ct.cast(buf, vp), len(key2_le_body), 0, 2)
        os_ = Stream()
        alloc = ct.cast(lib.dds_cdrstream_default_allocator, vp)
        lib.dds_ostreamBE_init(ct.byref(os_), alloc, 16, ver)
        lib.dds_stream_extract_keyBE_from_key(ct.byref(is_), ct.byref(os_), 1, alloc, self.cdrdesc)
        out = ct.string_at(os_.buf, os_.index)
        lib.dds_ostreamBE_fini(ct.byref(os_), alloc)
        return out

    def keyhash(self, sd):
        kh = ct.create_string_buffer(16)
        self.o.lib.ddsi_serdata_get_keyhash(sd, kh, False)
        return kh.raw

    def py_keyhash(self, data):
        """Key hash as computed by the binding's own sertype (ddspy) for Python-encoded bytes."""
        sd = self._from_ser(self.pysertype, data)
        if not sd:
            return None
        return self.keyhash(sd)


class Oracle:
    def __init__(self):
        self.lib = _load()
        self.dp = DomainParticipant(0)
        self.keep = []  # buffers the C core may still point into; freed at exit
        self.n = 0

    def ctype(self, cls):
        self.n += 1
        return CType(self, cls, self.n)
