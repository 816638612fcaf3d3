#pragma once
// Helpers shared by the device-profile tests: requests, replies, clock.

#include <chrono>
#include <cstdint>
#include <initializer_list>
#include <string>
#include <vector>

#include "vectors.hpp"
#include "engine/profiles/device_profile.hpp"
#include "engine/register_image.hpp"
#include "protocol/modbus_pdu.hpp"

namespace fbt {

namespace fe = fieldbridge::engine;
namespace fp = fieldbridge::protocol;
namespace fw = fieldbridge::protocol::wtec;

/// An arbitrary monotonic instant.
inline fe::TimePoint t0() { return fe::TimePoint{} + std::chrono::hours{1}; }

inline fp::Request read_holding(std::uint16_t address, std::uint16_t count) {
    return fp::ReadRegistersRequest{fp::fc::read_holding_registers, address, count};
}
inline fp::Request read_input(std::uint16_t address, std::uint16_t count) {
    return fp::ReadRegistersRequest{fp::fc::read_input_registers, address, count};
}
inline fp::Request read_bits(std::uint8_t function, std::uint16_t address, std::uint16_t count) {
    return fp::ReadBitsRequest{function, address, count};
}
inline fp::Request write_single(std::uint16_t address, std::uint16_t value) {
    return fp::WriteSingleRegisterRequest{address, value};
}
inline fp::Request write_multiple(std::uint16_t address, std::vector<std::uint16_t> values) {
    return fp::WriteMultipleRegistersRequest{address, std::move(values)};
}

inline fe::Reply modbus(fp::Response response) { return fe::Reply{std::move(response)}; }
inline fe::Reply registers(std::uint8_t function, std::vector<std::uint16_t> values) {
    return modbus(fp::ReadRegistersResponse{function, std::move(values)});
}
inline fe::Reply device_exception(std::uint8_t function, fp::ExceptionCode code) {
    return modbus(fp::ExceptionResponse{function, code});
}
inline fe::Reply ascii(fw::Reply reply) { return fe::Reply{std::move(reply)}; }

/// The Modbus request of a payload (fails the test when it is ASCII).
inline const fp::Request& request_of(const fe::Payload& payload) {
    return std::get<fe::ModbusPayload>(payload).request;
}
inline const fw::Command& command_of(const fe::Payload& payload) {
    return std::get<fe::AsciiPayload>(payload).command;
}

/// "10 06 10 00 01 02 00 01" (tests/unit/protocol/vectors.hpp).
using fieldbridge::test::hex;

/// The PDU bytes of the request a payload carries.
inline std::string pdu_hex(const fe::Payload& payload) { return hex(fp::encode_request(request_of(payload))); }

inline std::vector<std::uint16_t> values_of(const fe::RegisterImage& image, fe::Table table, std::uint16_t address,
                                            std::uint16_t count) {
    std::vector<std::uint16_t> out;
    for (std::uint16_t i = 0; i < count; ++i) {
        out.push_back(image.value(table, static_cast<std::uint16_t>(address + i)).value_or(0xDEAD));
    }
    return out;
}

/// Field value of a decoded state (fails with a message when absent).
template <typename T>
T field(const fe::DecodedState& state, std::string_view name) {
    const fe::Field* f = state.find(name);
    if (f == nullptr) {
        throw std::runtime_error("no field " + std::string{name});
    }
    return std::get<T>(f->value);
}

}  // namespace fbt
