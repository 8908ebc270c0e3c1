// Hand-written type support for the interop suite's @appendable ShapeType on Fast DDS 2.9.
//
// Written by hand rather than with fastddsgen 2.3 because that generator (with Fast CDR 1.0) only
// emits XCDR1, and Fast DDS 2.9's TopicDataType::serialize has no data-representation argument:
// this type support is told at construction which encoding to write (-x 1|2), and reads both.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include <fastdds/dds/topic/TopicDataType.hpp>
#include <fastrtps/utils/md5.h>

struct ShapeType {
    std::string color;
    int32_t x = 0;
    int32_t y = 0;
    int32_t shapesize = 0;
    std::vector<uint8_t> additional_payload_size;
};

class ShapeTypeSupport : public eprosima::fastdds::dds::TopicDataType {
public:
    explicit ShapeTypeSupport(bool xcdr2);

    bool serialize(void* data, eprosima::fastrtps::rtps::SerializedPayload_t* payload) override;
    bool deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload, void* data) override;
    std::function<uint32_t()> getSerializedSizeProvider(void* data) override;
    void* createData() override { return new ShapeType(); }
    void deleteData(void* data) override { delete static_cast<ShapeType*>(data); }
    bool getKey(void* data, eprosima::fastrtps::rtps::InstanceHandle_t* ihandle, bool force_md5 = false) override;

    /// Encapsulated size (header included) of `s` in the configured encoding.
    uint32_t encoded_size(const ShapeType& s) const;

    /// Encodes `s` (encapsulation header first) into `out`; returns the byte count.
    uint32_t encode(const ShapeType& s, uint8_t* out) const;

    /// Decodes an encapsulated ShapeType in XCDR1 or XCDR2, either byte order.
    static bool decode(const uint8_t* in, uint32_t len, ShapeType& s);

private:
    bool xcdr2_;
};
