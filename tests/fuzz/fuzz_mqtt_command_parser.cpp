// The MQTT command parser (northbound/mqtt/command_parser.hpp, parse_command) as the
// bridge calls it for a `<prefix>/<device>/cmd` payload: with the device's operations
// (its profile's) and its register image (WTEC `grip` / `release` read the init direction).
// A parsed command's requests go to the device as they are, so each must encode;
// a refusal must say why. The op and the refusal's message reach the log: escaped for
// it (core/log_text.hpp), nothing of them may need escaping any more (one printable line).
// Input: one byte choosing the device type's operations, one byte choosing how many registers
// (0-3) the image holds, 5 bytes per register (table, address, value), then the payload.

#include <cstddef>
#include <cstdint>
#include <iterator>
#include <stdexcept>
#include <string_view>
#include <variant>
#include <vector>

#include "fuzz_input.hpp"
#include "core/error.hpp"
#include "core/log_text.hpp"
#include "engine/profiles/excd_profile.hpp"
#include "engine/profiles/wtec_common.hpp"
#include "engine/profiles/xeg_profile.hpp"
#include "northbound/mqtt/command_parser.hpp"
#include "northbound/upstream/r6_operations.hpp"

namespace {

namespace mqtt = fieldbridge::northbound::mqtt;
namespace engine = fieldbridge::engine;

/// Every device type's operations (wtec-rtu and wtec-ascii share theirs; a generic
/// Modbus device has only the raw register ops).
const engine::OperationSet operation_sets[] = {engine::xeg_operations(), engine::excd_operations(),
                                               engine::wtec_operations(),
                                               fieldbridge::northbound::r6::r6_operations(), engine::OperationSet{}};
constexpr engine::Table tables[] = {engine::Table::coils, engine::Table::discrete_inputs, engine::Table::holding,
                                    engine::Table::input};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    fieldbridge::fuzz::FuzzInput input(data, size);
    const auto& set = operation_sets[input.byte() % std::size(operation_sets)];
    std::vector<mqtt::RawRegister> registers(input.byte() % 4);
    for (auto& r : registers) {
        r.table = tables[input.byte() % std::size(tables)];
        r.address = static_cast<std::uint16_t>(input.byte() << 8 | input.byte());
        r.value = static_cast<std::uint16_t>(input.byte() << 8 | input.byte());
    }
    const auto payload_bytes = input.rest();
    const std::string_view payload(reinterpret_cast<const char*>(payload_bytes.data()), payload_bytes.size());

    const auto result = mqtt::parse_command(payload, set, registers);
    const auto loggable = [](std::string_view text) {
        return !fieldbridge::core::needs_log_escape(fieldbridge::core::escape_log_text(text));
    };
    if (const auto* parsed = std::get_if<mqtt::ParsedCommand>(&result)) {
        FB_FUZZ_CHECK(loggable(parsed->op));
        FB_FUZZ_CHECK(!parsed->requests.empty() && !parsed->op.empty());
        FB_FUZZ_CHECK(parsed->id.is_string() || parsed->id.is_number());
        for (const auto& request : parsed->requests) {
            bool encodes = true;  // else a parsed command the wire cannot carry
            try {
                (void)fieldbridge::protocol::encode_request(request);
            } catch (const fieldbridge::core::InvalidArgument&) {
                encodes = false;
            }
            FB_FUZZ_CHECK(encodes);
        }
    } else {
        const auto& error = std::get<mqtt::CommandError>(result);
        FB_FUZZ_CHECK(!error.message.empty());
        FB_FUZZ_CHECK(loggable(error.message) && loggable(error.op));
    }
    return 0;
}
