#include "vectors.hpp"

#include <yaml-cpp/yaml.h>

#include <sstream>
#include <stdexcept>

namespace fieldbridge::test {

const std::vector<Vector>& all_vectors() {
    static const std::vector<Vector> vectors = [] {
        std::vector<Vector> out;
        const YAML::Node root = YAML::LoadFile(FIELDBRIDGE_VECTORS_FILE);
        for (const auto& node : root) {
            Vector v;
            v.protocol = node["protocol"].as<std::string>();
            v.device = node["device"].as<std::string>();
            v.what = node["what"].as<std::string>();
            v.request = node["request"].as<std::string>();
            if (node["response"] && !node["response"].IsNull()) {
                v.response = node["response"].as<std::string>();
            }
            v.request_crc_ok = node["request_crc_ok"].as<bool>();
            if (node["response_crc_ok"]) v.response_crc_ok = node["response_crc_ok"].as<bool>();
            out.push_back(std::move(v));
        }
        if (out.size() < 50) throw std::runtime_error("vectors.yaml: fewer vectors than expected");
        return out;
    }();
    return vectors;
}

protocol::Bytes parse_hex(const std::string& spaced_hex) {
    protocol::Bytes out;
    std::istringstream in(spaced_hex);
    std::string token;
    while (in >> token) out.push_back(static_cast<std::uint8_t>(std::stoul(token, nullptr, 16)));
    return out;
}

std::string hex(protocol::ByteView bytes) {
    static constexpr char digits[] = "0123456789ABCDEF";
    std::string out;
    for (const auto b : bytes) {
        if (!out.empty()) out.push_back(' ');
        out.push_back(digits[b >> 4]);
        out.push_back(digits[b & 0x0F]);
    }
    return out;
}

}  // namespace fieldbridge::test
