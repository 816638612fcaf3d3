// Sparkplug B NCMD/DCMD payloads (northbound/sparkplug/command_decoder.hpp, and under it
// payload_codec.hpp's decode): the bytes a host, or anyone on the broker, publishes to
// the node's command topics. Input: the payload.

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "core/log_text.hpp"
#include "fuzz_input.hpp"
#include "northbound/sparkplug/command_decoder.hpp"
#include "northbound/sparkplug/payload_codec.hpp"

namespace sp = fieldbridge::northbound::sparkplug;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view bytes(reinterpret_cast<const char*>(data), size);
    const sp::CommandLimits limits;
    const sp::CommandResult result = sp::decode_command(bytes, limits);
    if (!result.ok()) {
        FB_FUZZ_CHECK(!result.error.empty());
        // The reason may quote the input; escaped, it is one line for the log.
        FB_FUZZ_CHECK(fieldbridge::core::escape_log_text(result.error).find('\n') == std::string::npos);
        return 0;
    }
    const sp::Command& command = *result.command;
    FB_FUZZ_CHECK(!command.metrics.empty());
    FB_FUZZ_CHECK(command.metrics.size() <= limits.max_metrics);
    for (const sp::CommandMetric& metric : command.metrics) {
        FB_FUZZ_CHECK(metric.metric.name || metric.metric.alias);
        FB_FUZZ_CHECK(!metric.metric.name || !metric.metric.name->empty());
        FB_FUZZ_CHECK(!metric.metric.name || metric.metric.name->size() <= limits.max_string_bytes);
        FB_FUZZ_CHECK(!std::holds_alternative<std::monostate>(metric.value));
        if (const auto* text = std::get_if<std::string>(&metric.value)) {
            FB_FUZZ_CHECK(text->size() <= limits.max_string_bytes);
        }
    }
    // The command, encoded again, reads back as itself: the encoder writes what the
    // decoder accepted, and a second pass changes nothing (an Int8 written in one byte
    // grows to its 32-bit form, hence the wider byte limit).
    const std::string once = sp::encode(sp::command_payload(command));
    sp::CommandLimits wider = limits;
    wider.max_bytes = 8 * limits.max_bytes;
    const sp::CommandResult again = sp::decode_command(once, wider);
    FB_FUZZ_CHECK(again.ok());
    FB_FUZZ_CHECK(again.command->metrics.size() == command.metrics.size());
    FB_FUZZ_CHECK(sp::encode(sp::command_payload(*again.command)) == once);
    return 0;
}
