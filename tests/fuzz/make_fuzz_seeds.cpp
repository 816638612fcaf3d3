// Writes the seed corpora of the harnesses (docs/fuzzing.md), each input in the
// layout its harness reads:
// - from the manuals' frames (tests/vectors/vectors.yaml): the MBAP framer, the RTU
//   reply framer, the PDU codec and the WTEC ASCII scanner;
// - from the example configurations (config/*.yaml): the config loader;
// - from tests/fuzz/mqtt_commands.txt (the examples of docs/mqtt.md): the MQTT
//   command parser;
// - built here with the codec: a few Sparkplug B commands, for the Sparkplug command
//   decoder.
// Usage: make_fuzz_seeds <output directory>; one subdirectory per harness.

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "northbound/sparkplug/command_decoder.hpp"
#include "northbound/sparkplug/payload_codec.hpp"
#include "protocol/mbap_frame.hpp"
#include "protocol/wtec_ascii_commands.hpp"
#include "protocol/wtec_ascii_frame.hpp"
#include "vectors.hpp"

namespace {

namespace fs = std::filesystem;
namespace protocol = fieldbridge::protocol;
namespace wtec = protocol::wtec;
using protocol::Bytes;
using fieldbridge::test::Vector;

class SeedWriter {
public:
    explicit SeedWriter(fs::path dir) : dir_(std::move(dir)) { fs::create_directories(dir_); }

    void write(const Bytes& seed) {
        const auto path = dir_ / ("seed-" + std::to_string(++count_));
        std::ofstream out(path, std::ios::binary);
        out.write(reinterpret_cast<const char*>(seed.data()), static_cast<std::streamsize>(seed.size()));
        if (!out) throw std::runtime_error("cannot write " + path.string());
    }
    [[nodiscard]] int count() const { return count_; }

private:
    fs::path dir_;
    int count_ = 0;
};

Bytes concat(std::initializer_list<protocol::ByteView> parts) {
    Bytes out;
    for (const auto part : parts) out.insert(out.end(), part.begin(), part.end());
    return out;
}

Bytes text_bytes(const std::string& text) { return Bytes(text.begin(), text.end()); }

/// RTU ADU -> PDU (without address and CRC).
protocol::ByteView pdu_of(const Bytes& adu) { return protocol::ByteView(adu).subspan(1, adu.size() - 3); }

void modbus_seeds(const std::vector<Vector>& vectors, const fs::path& out) {
    SeedWriter mbap(out / "fuzz_mbap_framer");
    SeedWriter rtu(out / "fuzz_rtu_response_framer");
    SeedWriter pdu(out / "fuzz_modbus_pdu");
    Bytes stream{0};  // every request of the manuals back to back, read at once
    std::uint16_t transaction = 0;
    for (const auto& v : vectors) {
        if (v.protocol != "modbus-rtu" || !v.request_crc_ok) continue;
        const Bytes request = fieldbridge::test::parse_hex(v.request);
        if (request.size() < 4) continue;
        const auto request_pdu = pdu_of(request);
        const Bytes as_mbap = protocol::encode_mbap(++transaction, fieldbridge::core::UnitId{request[0]}, request_pdu);
        mbap.write(concat({Bytes{0x11}, as_mbap}));
        stream.insert(stream.end(), as_mbap.begin(), as_mbap.end());
        if (!v.response || !v.response_crc_ok) continue;
        const Bytes response = fieldbridge::test::parse_hex(*v.response);
        if (response.size() < 4) continue;
        mbap.write(concat({Bytes{0x00}, protocol::encode_mbap(transaction, fieldbridge::core::UnitId{response[0]}, pdu_of(response))}));
        const Bytes length{static_cast<std::uint8_t>(request_pdu.size())};
        // Split byte 0x00, then the same with 3 bytes of noise ahead of the reply.
        rtu.write(concat({Bytes{0x00}, length, request_pdu, Bytes{request[0]}, response}));
        rtu.write(concat({Bytes{0x07}, length, request_pdu, Bytes{request[0]}, Bytes{0x00, 0xFF, request[0]}, response}));
        pdu.write(concat({length, request_pdu, pdu_of(response)}));
    }
    mbap.write(stream);
    std::cout << "make_fuzz_seeds: " << mbap.count() << " MBAP, " << rtu.count() << " RTU reply, " << pdu.count()
              << " PDU seeds\n";
}

void wtec_seeds(const std::vector<Vector>& vectors, const fs::path& out) {
    SeedWriter scanner(out / "fuzz_wtec_ascii");
    for (const auto& v : vectors) {
        if (v.protocol != "wtec-ascii" || !v.request_crc_ok) continue;
        const auto request = wtec::decode_frame_body(v.request);
        if (!request.complete()) continue;
        const auto command = wtec::decode_command(request.value);
        if (!command.complete()) continue;
        // The harness picks the command by its index in wtec::Command.
        const Bytes context{0x00, static_cast<std::uint8_t>(command.value.index()), request.value.address, 0, 0, 0, 0};
        scanner.write(concat({context, text_bytes(v.request + "\r\n")}));
        if (v.response && v.response_crc_ok) {
            scanner.write(concat({context, text_bytes(*v.response + "\r\n")}));
            scanner.write(concat({context, text_bytes("\r\n" + v.request + "\r\n" + *v.response + "\r\n")}));
        }
    }
    std::cout << "make_fuzz_seeds: " << scanner.count() << " WTEC ASCII seeds\n";
}

void config_seeds(const fs::path& config_dir, const fs::path& out) {
    SeedWriter loader(out / "fuzz_config_loader");
    for (const auto& entry : fs::directory_iterator(config_dir)) {
        if (entry.path().extension() != ".yaml") continue;
        std::ifstream in(entry.path(), std::ios::binary);
        std::ostringstream text;
        text << in.rdbuf();
        loader.write(text_bytes(text.str()));
    }
    std::cout << "make_fuzz_seeds: " << loader.count() << " configuration seeds\n";
}

/// Lines "<set> <payload>": set 0 xeg, 1 excd, 2 wtec, 3 r6, 4 generic (the harness's
/// order). WTEC seeds carry holding 0x0300 = 1 (init direction) so grip/release parse.
void mqtt_seeds(const fs::path& commands_file, const fs::path& out) {
    SeedWriter parser(out / "fuzz_mqtt_command_parser");
    std::ifstream in(commands_file);
    if (!in) throw std::runtime_error("cannot read " + commands_file.string());
    std::string line;
    while (std::getline(in, line)) {
        if (line.empty() || line[0] == '#') continue;
        const auto space = line.find(' ');
        const auto set = static_cast<std::uint8_t>(std::stoi(line.substr(0, space)));
        const Bytes image = set == 2 ? Bytes{1, 2, 0x03, 0x00, 0x00, 0x01} : Bytes{0};
        parser.write(concat({Bytes{set}, image, text_bytes(line.substr(space + 1))}));
    }
    std::cout << "make_fuzz_seeds: " << parser.count() << " MQTT command seeds\n";
}

/// A few commands a Sparkplug host sends (docs/sparkplug.md, "Commands"): a rebirth
/// request, writes by alias with and without datatype, by name, several at once.
void sparkplug_seeds(const fs::path& out) {
    namespace sp = fieldbridge::northbound::sparkplug;
    SeedWriter commands(out / "fuzz_sparkplug_command");
    const auto write = [&](std::vector<sp::CommandMetric> metrics) {
        const std::string bytes = sp::encode(sp::command_payload(sp::Command{1700000000000, std::move(metrics)}));
        commands.write(text_bytes(bytes));
    };
    using T = sp::DataType;
    // Built one by one: GCC 12 at -O3 (the arm64 cross build) warns a false
    // -Wmaybe-uninitialized on optionals destroyed in a braced list of temporaries.
    const auto metric = [](std::optional<std::string> name, std::optional<std::uint64_t> alias,
                           std::optional<T> type, sp::Value value) {
        sp::CommandMetric m;
        m.metric.name = std::move(name);
        m.metric.alias = alias;
        m.datatype = type;
        m.value = std::move(value);
        return m;
    };
    const auto one = [&write](sp::CommandMetric m) {
        std::vector<sp::CommandMetric> metrics;
        metrics.push_back(std::move(m));
        write(std::move(metrics));
    };
    one(metric("Node Control/Rebirth", std::nullopt, T::boolean, true));
    one(metric(std::nullopt, 4, T::uint16, std::uint64_t{80}));
    one(metric(std::nullopt, 4, std::nullopt, std::uint64_t{80}));
    one(metric("force_pct", std::nullopt, T::int16, static_cast<std::uint64_t>(-5)));
    std::vector<sp::CommandMetric> several;
    several.push_back(metric("setpoint", 9, T::float32, 12.5f));
    several.push_back(metric("ratio", std::nullopt, T::float64, 0.25));
    several.push_back(metric("label", std::nullopt, T::string, std::string("tool 2")));
    several.push_back(metric(std::nullopt, 11, T::int64, static_cast<std::uint64_t>(-1)));
    write(std::move(several));
    std::cout << "make_fuzz_seeds: " << commands.count() << " Sparkplug command seeds\n";
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 2) {
        std::cerr << "usage: make_fuzz_seeds <output directory>\n";
        return 2;
    }
    try {
        const fs::path out = argv[1];
        const auto& vectors = fieldbridge::test::all_vectors();
        modbus_seeds(vectors, out);
        wtec_seeds(vectors, out);
        config_seeds(fs::path(FIELDBRIDGE_SOURCE_DIR) / "config", out);
        mqtt_seeds(fs::path(FIELDBRIDGE_SOURCE_DIR) / "tests/fuzz/mqtt_commands.txt", out);
        sparkplug_seeds(out);
    } catch (const std::exception& error) {
        std::cerr << "make_fuzz_seeds: " << error.what() << "\n";
        return 1;
    }
    return 0;
}
