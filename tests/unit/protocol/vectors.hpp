#pragma once
// The manuals' example frames, copied from the spec into tests/vectors/vectors.yaml,
// loaded for table-driven tests. Both RTU (hex bytes) and WTEC ASCII (text) frames.

#include <optional>
#include <string>
#include <vector>

#include "protocol/bytes.hpp"

namespace fieldbridge::test {

struct Vector {
    std::string protocol;  ///< "modbus-rtu" or "wtec-ascii"
    std::string device;
    std::string what;
    std::string request;                 ///< as written in the YAML
    std::optional<std::string> response; ///< nullopt when the manual shows none
    bool request_crc_ok = true;
    bool response_crc_ok = true;
};

/// All vectors of the file (FIELDBRIDGE_VECTORS_FILE, set by CMake).
[[nodiscard]] const std::vector<Vector>& all_vectors();

/// "02 10 06 00" -> bytes.
[[nodiscard]] protocol::Bytes parse_hex(const std::string& spaced_hex);

/// bytes -> "02 10 06 00" (upper-case, for failure messages).
[[nodiscard]] std::string hex(protocol::ByteView bytes);

}  // namespace fieldbridge::test
