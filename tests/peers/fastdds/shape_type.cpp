#include "shape_type.hpp"

#include <cstdio>
#include <cstdlib>

using eprosima::fastrtps::rtps::InstanceHandle_t;
using eprosima::fastrtps::rtps::SerializedPayload_t;

namespace {

// Representation identifiers (XTypes 1.3 §7.6.3.1.2), little-endian variants.
constexpr uint16_t REP_CDR_LE = 0x0001;
constexpr uint16_t REP_D_CDR2_LE = 0x0009;

uint32_t align4(uint32_t n) { return (n + 3u) & ~3u; }

void put_u32(uint8_t* p, uint32_t v) { std::memcpy(p, &v, 4); }  // host order: x86 is little-endian

class Reader {
public:
    Reader(const uint8_t* p, uint32_t len, bool swap) : p_(p), len_(len), swap_(swap) {}
    bool u32(uint32_t& v) {
        pos_ = align4(pos_);
        if (pos_ + 4 > len_) return false;
        std::memcpy(&v, p_ + pos_, 4);
        if (swap_) v = __builtin_bswap32(v);
        pos_ += 4;
        return true;
    }
    bool bytes(uint8_t* out, uint32_t n) {
        if (n > len_ - pos_) return false;
        if (n) std::memcpy(out, p_ + pos_, n);
        pos_ += n;
        return true;
    }
    bool skip(uint32_t n) {
        if (n > len_ - pos_) return false;
        pos_ += n;
        return true;
    }
    uint32_t pos() const { return pos_; }

private:
    const uint8_t* p_;
    uint32_t len_;
    bool swap_;
    uint32_t pos_ = 0;
};

// Size of the members (no header, no DHEADER), starting at offset 0 of the CDR stream.
uint32_t body_size(const ShapeType& s) {
    uint32_t n = 4 + static_cast<uint32_t>(s.color.size()) + 1;
    n = align4(n) + 12;
    n += 4 + static_cast<uint32_t>(s.additional_payload_size.size());
    return n;
}

}  // namespace

ShapeTypeSupport::ShapeTypeSupport(bool xcdr2) : xcdr2_(xcdr2) {
    setName("ShapeType");
    // Payloads grow on demand (writer history uses PREALLOCATED_WITH_REALLOC); this is the start size.
    m_typeSize = 4 + 4 + 4 + 129 + 3 + 12 + 4 + 256;
    m_isGetKeyDefined = true;
    // No TypeObject/TypeInformation: the other side matches on the type name.
    auto_fill_type_object(false);
    auto_fill_type_information(false);
}

uint32_t ShapeTypeSupport::encoded_size(const ShapeType& s) const {
    return align4(4 + (xcdr2_ ? 4 : 0) + body_size(s));
}

uint32_t ShapeTypeSupport::encode(const ShapeType& s, uint8_t* out) const {
    const uint32_t total = encoded_size(s);
    std::memset(out, 0, total);
    const uint16_t rep = xcdr2_ ? REP_D_CDR2_LE : REP_CDR_LE;
    out[0] = static_cast<uint8_t>(rep >> 8);
    out[1] = static_cast<uint8_t>(rep & 0xff);
    const uint32_t body = body_size(s);
    const uint32_t unpadded = 4 + (xcdr2_ ? 4 : 0) + body;
    out[3] = static_cast<uint8_t>(total - unpadded);  // options: padding count in the low 2 bits
    uint8_t* p = out + 4;
    if (xcdr2_) {
        put_u32(p, body);  // DHEADER of the appendable struct
        p += 4;
    }
    const uint8_t* origin = p;
    put_u32(p, static_cast<uint32_t>(s.color.size()) + 1);
    p += 4;
    std::memcpy(p, s.color.data(), s.color.size());
    p += s.color.size() + 1;
    p = const_cast<uint8_t*>(origin) + align4(static_cast<uint32_t>(p - origin));
    put_u32(p, static_cast<uint32_t>(s.x));
    put_u32(p + 4, static_cast<uint32_t>(s.y));
    put_u32(p + 8, static_cast<uint32_t>(s.shapesize));
    p += 12;
    put_u32(p, static_cast<uint32_t>(s.additional_payload_size.size()));
    p += 4;
    if (!s.additional_payload_size.empty())
        std::memcpy(p, s.additional_payload_size.data(), s.additional_payload_size.size());
    return total;
}

bool ShapeTypeSupport::decode(const uint8_t* in, uint32_t len, ShapeType& s) {
    if (len < 4) return false;
    const uint16_t rep = static_cast<uint16_t>((in[0] << 8) | in[1]);
    const bool little = (rep & 1) != 0;
    bool delimited;
    switch (rep & ~1u) {
        case 0x0000: delimited = false; break;  // CDR (XCDR1)
        case 0x0006: delimited = false; break;  // CDR2 (final) tolerated
        case 0x0008: delimited = true; break;   // D_CDR2 (appendable)
        default: return false;
    }
    Reader r(in + 4, len - 4, !little);
    uint32_t end = len - 4;
    if (delimited) {
        uint32_t dheader;
        if (!r.u32(dheader) || dheader > end - 4) return false;
        end = 4 + dheader;
    }
    uint32_t slen;
    if (!r.u32(slen) || slen == 0 || slen > 129) return false;
    std::string color(slen, '\0');
    if (!r.bytes(reinterpret_cast<uint8_t*>(&color[0]), slen)) return false;
    color.resize(slen - 1);
    s.color = color;
    s.x = s.y = s.shapesize = 0;
    s.additional_payload_size.clear();
    // A key-only payload (dispose/unregister without a key hash) ends after the key.
    if (align4(r.pos()) >= end) return true;
    uint32_t x, y, size, n;
    if (!r.u32(x) || !r.u32(y) || !r.u32(size)) return false;
    s.x = static_cast<int32_t>(x);
    s.y = static_cast<int32_t>(y);
    s.shapesize = static_cast<int32_t>(size);
    // An older (shorter) appendable ShapeType may end here.
    if (r.pos() >= end) return true;
    if (!r.u32(n) || n > end - r.pos()) return false;
    s.additional_payload_size.resize(n);
    return r.bytes(s.additional_payload_size.data(), n);
}

bool ShapeTypeSupport::serialize(void* data, SerializedPayload_t* payload) {
    const ShapeType& s = *static_cast<ShapeType*>(data);
    const uint32_t size = encoded_size(s);
    if (payload->max_size < size) payload->reserve(size);
    if (payload->max_size < size) return false;
    payload->length = encode(s, payload->data);
    payload->encapsulation = CDR_LE;
    return true;
}

bool ShapeTypeSupport::deserialize(SerializedPayload_t* payload, void* data) {
    const bool ok = decode(payload->data, payload->length, *static_cast<ShapeType*>(data));
    if (!ok && std::getenv("SHAPE_DEBUG") != nullptr) {
        std::fprintf(stderr, "deserialize failed: %u bytes:", payload->length);
        for (uint32_t i = 0; i < payload->length && i < 48; ++i) std::fprintf(stderr, " %02x", payload->data[i]);
        std::fprintf(stderr, "\n");
    }
    return ok;
}

std::function<uint32_t()> ShapeTypeSupport::getSerializedSizeProvider(void* data) {
    const ShapeType* s = static_cast<ShapeType*>(data);
    return [this, s]() { return encoded_size(*s); };
}

bool ShapeTypeSupport::getKey(void* data, InstanceHandle_t* ihandle, bool /*force_md5*/) {
    // Key hash (RTPS 2.5 §9.6.4.8): the key serialized big-endian; string<128> can exceed 16 bytes,
    // so the hash is always the MD5 of that serialization.
    const ShapeType& s = *static_cast<ShapeType*>(data);
    std::vector<uint8_t> key(4 + s.color.size() + 1, 0);
    const uint32_t slen = static_cast<uint32_t>(s.color.size()) + 1;
    key[0] = static_cast<uint8_t>(slen >> 24);
    key[1] = static_cast<uint8_t>(slen >> 16);
    key[2] = static_cast<uint8_t>(slen >> 8);
    key[3] = static_cast<uint8_t>(slen);
    std::memcpy(key.data() + 4, s.color.data(), s.color.size());
    MD5 md5;
    md5.init();
    md5.update(key.data(), static_cast<unsigned int>(key.size()));
    md5.finalize();
    for (int i = 0; i < 16; ++i) ihandle->value[i] = md5.digest[i];
    return true;
}
