// NCMD/DCMD payloads read by the command decoder (northbound/sparkplug/command_decoder.*).
#include <doctest/doctest.h>

#include "northbound/sparkplug/command_decoder.hpp"
#include "northbound/sparkplug/payload_codec.hpp"
#include "wire_builder.hpp"

namespace {

namespace sp = fieldbridge::northbound::sparkplug;
using namespace spb_test;

}  // namespace

TEST_CASE("sparkplug command: by alias, by name, with or without datatype") {
    // A host's DCMD: alias 4 (UInt16 given) = 80, name "force_pct" (no datatype, int_value) = 30,
    // "Node Control/Rebirth" = true.
    const std::string input = field_varint(1, 1700000000000) +
                              field_bytes(2, field_varint(2, 4) + field_varint(4, 6) + field_varint(10, 80)) +
                              field_bytes(2, field_bytes(1, "force_pct") + field_varint(10, 30)) +
                              field_bytes(2, field_bytes(1, "Node Control/Rebirth") + field_varint(4, 11) +
                                                 field_varint(14, 1));
    const auto r = sp::decode_command(input);
    REQUIRE(r.ok());
    const auto& metrics = r.command->metrics;
    REQUIRE(metrics.size() == 3);
    CHECK(metrics[0].metric == sp::MetricReference{std::nullopt, 4});
    CHECK(metrics[0].datatype == sp::DataType::uint16);
    CHECK(std::get<std::uint64_t>(metrics[0].value) == 80);
    CHECK(metrics[1].metric == sp::MetricReference{"force_pct", std::nullopt});
    CHECK_FALSE(metrics[1].datatype.has_value());
    CHECK(std::get<std::uint64_t>(metrics[1].value) == 30);
    CHECK(std::get<bool>(metrics[2].value));
    CHECK(r.command->timestamp == 1700000000000u);
    // What command_payload() makes of it decodes to the same command.
    const auto again = sp::decode_command(sp::encode(sp::command_payload(*r.command)));
    REQUIRE(again.ok());
    CHECK(*again.command == *r.command);
}

TEST_CASE("sparkplug command: refusals name the metric and the reason") {
    const auto refused = [](const std::string& input) {
        const auto r = sp::decode_command(input);
        CHECK_FALSE(r.ok());
        return r.error;
    };
    CHECK(refused(std::string("\x12\x05", 2)) ==
          "the payload does not decode: byte 0: Payload.metrics: length 5 runs past the end (0 bytes left)");
    CHECK(refused(field_varint(1, 5)) == "the command holds no metric");
    CHECK(refused(field_bytes(2, field_varint(11, 1))) == "metric 0 has neither a name nor an alias");
    CHECK(refused(field_bytes(2, field_bytes(1, "") + field_varint(11, 1))) == "metric 0 '' has an empty name");
    CHECK(refused(field_bytes(2, field_varint(2, 9))) == "metric 0 (alias 9) has no value");
    CHECK(refused(field_bytes(2, field_varint(2, 9) + field_varint(7, 1) + field_varint(11, 1))) ==
          "metric 0 (alias 9) has no value");  // is_null wins
    CHECK(refused(field_bytes(2, field_varint(2, 9) + field_varint(4, 9) + field_bytes(15, "x"))) ==
          "the payload does not decode: metric 0 (alias 9): string_value does not hold a Float");
}

TEST_CASE("sparkplug command: limits on bytes, metrics and strings") {
    std::string many;
    for (int i = 0; i < 257; ++i) many += field_bytes(2, field_varint(2, 1) + field_varint(11, 1));
    CHECK(sp::decode_command(many).error.find("more than the 256 elements allowed") != std::string::npos);
    CHECK(sp::decode_command(many, sp::CommandLimits{.max_metrics = 300}).ok());
    const std::string long_name = field_bytes(2, field_bytes(1, std::string(1025, 'a')) + field_varint(11, 1));
    CHECK(sp::decode_command(long_name).error.find("length 1025 is over the 1024 allowed") != std::string::npos);
    const std::string big(64 * 1024 + 1, '\0');
    CHECK(sp::decode_command(big).error == "the payload does not decode: 65537 bytes, over the 65536 allowed");
}
