// Modbus PDU codec: helpers, requests and request-length prediction. Responses are in
// modbus_pdu_response.cpp. Section numbers cite the Modbus Application Protocol
// Specification V1.1b3.
#include "protocol/modbus_pdu.hpp"

#include <stdexcept>
#include <string>
#include <variant>

#include "core/error.hpp"
#include "protocol/modbus_pdu_detail.hpp"

namespace fieldbridge::protocol {

// ---- detail helpers ---------------------------------------------------------------

namespace detail {

std::string function_name(std::uint8_t function) {
    constexpr char digits[] = "0123456789ABCDEF";
    std::string name = "FC";
    name.push_back(digits[function >> 4]);
    name.push_back(digits[function & 0x0F]);
    return name;
}

void reject(std::uint8_t function, const char* kind, const std::string& what) {
    throw core::InvalidArgument("Modbus " + function_name(function) + " " + kind + ": " + what);
}

void check_quantity(std::uint8_t function, const char* kind, const char* field, std::size_t value,
                    std::size_t max) {
    if (value < 1 || value > max) {
        reject(function, kind,
               std::string(field) + " " + std::to_string(value) + " is outside 1.." +
                   std::to_string(max) + " (split the transfer or fix the request)");
    }
}

void put_bits(Bytes& out, const std::vector<bool>& bits) {
    for (std::size_t first = 0; first < bits.size(); first += 8) {
        unsigned byte = 0;
        for (std::size_t bit = 0; bit < 8 && first + bit < bits.size(); ++bit) {
            if (bits[first + bit]) byte |= 1U << bit;
        }
        out.push_back(static_cast<std::uint8_t>(byte));
    }
}

std::vector<bool> get_bits(ByteView bytes, std::size_t count) {
    std::vector<bool> bits(count);
    for (std::size_t i = 0; i < count; ++i) bits[i] = ((bytes[i / 8] >> (i % 8)) & 1U) != 0;
    return bits;
}

void put_registers(Bytes& out, const std::vector<std::uint16_t>& values) {
    for (const std::uint16_t value : values) put_u16_be(out, value);
}

std::vector<std::uint16_t> get_registers(ByteView bytes) {
    std::vector<std::uint16_t> values(bytes.size() / 2);
    for (std::size_t i = 0; i < values.size(); ++i) values[i] = get_u16_be(bytes, 2 * i);
    return values;
}

}  // namespace detail

using namespace detail;

namespace {

/// A function code a request may carry: 1..127 (0 is not a function and 128..255 are
/// reserved for exception replies, 4.1).
bool is_request_function(std::uint8_t function) noexcept {
    return function != 0 && (function & fc::exception_flag) == 0;
}

constexpr const char* request_kind = "request";

}  // namespace

std::uint8_t function_of(const Request& request) noexcept {
    return std::visit(
        Overloaded{
            [](const ReadBitsRequest& r) { return r.function; },
            [](const ReadRegistersRequest& r) { return r.function; },
            [](const WriteSingleCoilRequest&) { return fc::write_single_coil; },
            [](const WriteSingleRegisterRequest&) { return fc::write_single_register; },
            [](const ReadExceptionStatusRequest&) { return fc::read_exception_status; },
            [](const WriteMultipleCoilsRequest&) { return fc::write_multiple_coils; },
            [](const WriteMultipleRegistersRequest&) { return fc::write_multiple_registers; },
            [](const MaskWriteRegisterRequest&) { return fc::mask_write_register; },
            [](const ReadWriteRegistersRequest&) { return fc::read_write_multiple_registers; },
            [](const OpaqueRequest& r) { return r.function; },
        },
        request);
}

core::FunctionCode function_code(const Request& request) noexcept { return core::FunctionCode{function_of(request)}; }

core::FunctionCode pdu_function(ByteView pdu) noexcept {
    return pdu.empty() ? core::FunctionCode{} : core::FunctionCode{pdu[0]};
}

bool is_write(core::FunctionCode function) noexcept {
    // Only function codes that the public Modbus specification defines as pure reads
    // (6.1-6.4, 6.7, 6.9, 6.10, 6.13, 6.14, 6.18, 6.19, 6.21) count as reads. Everything
    // else, including user-defined and unknown codes, may change the device and is
    // treated as a write: never retried automatically (product spec, section 3 rule 6).
    switch (static_cast<std::uint8_t>(function.value & ~fc::exception_flag)) {
        case fc::read_coils:
        case fc::read_discrete_inputs:
        case fc::read_holding_registers:
        case fc::read_input_registers:
        case fc::read_exception_status:
        case 0x0B:  // Get Comm Event Counter
        case 0x0C:  // Get Comm Event Log
        case 0x11:  // Report Server ID
        case 0x14:  // Read File Record
        case 0x18:  // Read FIFO Queue
        case 0x2B:  // Encapsulated Interface Transport (Read Device Identification)
            return false;
        default:
            return true;
    }
}

Bytes encode_request(const Request& request) {
    Bytes out;
    std::visit(
        Overloaded{
            [&out](const ReadBitsRequest& r) {
                if (r.function != fc::read_coils && r.function != fc::read_discrete_inputs) {
                    reject(r.function, request_kind, "a bit read must be FC01 or FC02");
                }
                check_quantity(r.function, request_kind, "bit count", r.count, max_read_bits);
                out.push_back(r.function);
                put_u16_be(out, r.address);
                put_u16_be(out, r.count);
            },
            [&out](const ReadRegistersRequest& r) {
                if (r.function != fc::read_holding_registers &&
                    r.function != fc::read_input_registers) {
                    reject(r.function, request_kind, "a register read must be FC03 or FC04");
                }
                check_quantity(r.function, request_kind, "register count", r.count,
                               max_read_registers);
                out.push_back(r.function);
                put_u16_be(out, r.address);
                put_u16_be(out, r.count);
            },
            [&out](const WriteSingleCoilRequest& r) {
                out.push_back(fc::write_single_coil);
                put_u16_be(out, r.address);
                put_u16_be(out, r.value ? coil_on : coil_off);
            },
            [&out](const WriteSingleRegisterRequest& r) {
                out.push_back(fc::write_single_register);
                put_u16_be(out, r.address);
                put_u16_be(out, r.value);
            },
            [&out](const ReadExceptionStatusRequest&) { out.push_back(fc::read_exception_status); },
            [&out](const WriteMultipleCoilsRequest& r) {
                check_quantity(fc::write_multiple_coils, request_kind, "coil count",
                               r.values.size(), max_write_coils);
                out.push_back(fc::write_multiple_coils);
                put_u16_be(out, r.address);
                put_u16_be(out, static_cast<std::uint16_t>(r.values.size()));
                out.push_back(static_cast<std::uint8_t>(bit_byte_count(r.values.size())));
                put_bits(out, r.values);
            },
            [&out](const WriteMultipleRegistersRequest& r) {
                check_quantity(fc::write_multiple_registers, request_kind, "register count",
                               r.values.size(), max_write_registers);
                out.push_back(fc::write_multiple_registers);
                put_u16_be(out, r.address);
                put_u16_be(out, static_cast<std::uint16_t>(r.values.size()));
                out.push_back(static_cast<std::uint8_t>(2 * r.values.size()));
                put_registers(out, r.values);
            },
            [&out](const MaskWriteRegisterRequest& r) {
                out.push_back(fc::mask_write_register);
                put_u16_be(out, r.address);
                put_u16_be(out, r.and_mask);
                put_u16_be(out, r.or_mask);
            },
            [&out](const ReadWriteRegistersRequest& r) {
                constexpr std::uint8_t function = fc::read_write_multiple_registers;
                check_quantity(function, request_kind, "read register count", r.read_count,
                               max_read_registers);
                check_quantity(function, request_kind, "write register count", r.values.size(),
                               max_rw_write_registers);
                out.push_back(function);
                put_u16_be(out, r.read_address);
                put_u16_be(out, r.read_count);
                put_u16_be(out, r.write_address);
                put_u16_be(out, static_cast<std::uint16_t>(r.values.size()));
                out.push_back(static_cast<std::uint8_t>(2 * r.values.size()));
                put_registers(out, r.values);
            },
            [&out](const OpaqueRequest& r) {
                if (!is_request_function(r.function)) {
                    reject(r.function, request_kind, "function code must be 1..127");
                }
                if (r.data.size() > max_pdu_size - 1) {
                    reject(r.function, request_kind,
                           std::to_string(r.data.size()) + " data bytes exceed the " +
                               std::to_string(max_pdu_size - 1) + " a PDU can carry");
                }
                out.push_back(r.function);
                out.insert(out.end(), r.data.begin(), r.data.end());
            },
        },
        request);
    return out;
}

namespace {

using RequestResult = DecodeResult<Request>;

bool in_range(std::size_t value, std::size_t max) noexcept { return value >= 1 && value <= max; }

/// FC01-06: function, address, count or value.
RequestResult decode_address_value(ByteView pdu) {
    const std::size_t size = pdu.size();
    if (size != address_value_pdu_size) return RequestResult::bad(DecodeError::bad_length, size);
    const std::uint8_t function = pdu[0];
    const std::uint16_t address = get_u16_be(pdu, 1);
    const std::uint16_t value = get_u16_be(pdu, 3);
    switch (function) {
        case fc::read_coils:
        case fc::read_discrete_inputs:
            if (!in_range(value, max_read_bits)) return RequestResult::bad(DecodeError::bad_value, size);
            return RequestResult::ok(ReadBitsRequest{function, address, value}, size);
        case fc::read_holding_registers:
        case fc::read_input_registers:
            if (!in_range(value, max_read_registers)) {
                return RequestResult::bad(DecodeError::bad_value, size);
            }
            return RequestResult::ok(ReadRegistersRequest{function, address, value}, size);
        case fc::write_single_coil:
            // 6.5: "A value of FF 00 hex requests the output to be ON. A value of 00 00
            // requests it to be OFF. All other values are illegal".
            if (value != coil_on && value != coil_off) {
                return RequestResult::bad(DecodeError::bad_value, size);
            }
            return RequestResult::ok(WriteSingleCoilRequest{address, value == coil_on}, size);
        default:
            return RequestResult::ok(WriteSingleRegisterRequest{address, value}, size);
    }
}

/// FC0F / FC10: function, address, count, byte count, data.
RequestResult decode_write_multiple(ByteView pdu) {
    const std::size_t size = pdu.size();
    if (size < write_multiple_header_size) return RequestResult::bad(DecodeError::bad_length, size);
    const std::uint8_t function = pdu[0];
    const std::uint16_t address = get_u16_be(pdu, 1);
    const std::uint16_t count = get_u16_be(pdu, 3);
    const std::size_t byte_count = pdu[5];
    const bool coils = function == fc::write_multiple_coils;
    if (!in_range(count, coils ? max_write_coils : max_write_registers)) {
        return RequestResult::bad(DecodeError::bad_value, size);
    }
    const std::size_t expected_bytes = coils ? bit_byte_count(count) : 2U * count;
    if (byte_count != expected_bytes || size != write_multiple_header_size + byte_count) {
        return RequestResult::bad(DecodeError::bad_length, size);
    }
    const ByteView data = pdu.subspan(write_multiple_header_size);
    if (coils) return RequestResult::ok(WriteMultipleCoilsRequest{address, get_bits(data, count)}, size);
    return RequestResult::ok(WriteMultipleRegistersRequest{address, get_registers(data)}, size);
}

/// FC17: function, read address, read count, write address, write count, byte count, data.
RequestResult decode_read_write(ByteView pdu) {
    const std::size_t size = pdu.size();
    if (size < read_write_header_size) return RequestResult::bad(DecodeError::bad_length, size);
    const std::uint16_t read_count = get_u16_be(pdu, 3);
    const std::uint16_t write_count = get_u16_be(pdu, 7);
    const std::size_t byte_count = pdu[9];
    if (!in_range(read_count, max_read_registers) || !in_range(write_count, max_rw_write_registers)) {
        return RequestResult::bad(DecodeError::bad_value, size);
    }
    if (byte_count != 2U * write_count || size != read_write_header_size + byte_count) {
        return RequestResult::bad(DecodeError::bad_length, size);
    }
    return RequestResult::ok(
        ReadWriteRegistersRequest{get_u16_be(pdu, 1), read_count, get_u16_be(pdu, 5),
                                  get_registers(pdu.subspan(read_write_header_size))},
        size);
}

PredictedLength known_length(std::size_t length) { return {DecodeStatus::complete, length}; }

}  // namespace

DecodeResult<Request> decode_request(ByteView pdu) {
    const std::size_t size = pdu.size();
    if (size == 0) return RequestResult::bad(DecodeError::bad_length, 0);
    if (size > max_pdu_size) return RequestResult::bad(DecodeError::oversize, size);
    const std::uint8_t function = pdu[0];
    if (!is_request_function(function)) return RequestResult::bad(DecodeError::bad_value, size);
    switch (function) {
        case fc::read_coils:
        case fc::read_discrete_inputs:
        case fc::read_holding_registers:
        case fc::read_input_registers:
        case fc::write_single_coil:
        case fc::write_single_register:
            return decode_address_value(pdu);
        case fc::read_exception_status:
            if (size != read_exception_status_request_size) {
                return RequestResult::bad(DecodeError::bad_length, size);
            }
            return RequestResult::ok(ReadExceptionStatusRequest{}, size);
        case fc::write_multiple_coils:
        case fc::write_multiple_registers:
            return decode_write_multiple(pdu);
        case fc::mask_write_register:
            if (size != mask_write_pdu_size) return RequestResult::bad(DecodeError::bad_length, size);
            return RequestResult::ok(MaskWriteRegisterRequest{get_u16_be(pdu, 1), get_u16_be(pdu, 3), get_u16_be(pdu, 5)},
                                     size);
        case fc::read_write_multiple_registers:
            return decode_read_write(pdu);
        default:
            return RequestResult::ok(OpaqueRequest{function, Bytes(pdu.begin() + 1, pdu.end())}, size);
    }
}

std::optional<PredictedLength> predict_request_pdu_length(ByteView pdu_prefix) {
    // libmodbus compute_meta_length_after_function / compute_data_length_after_meta:
    // fixed-size requests are known from the function code, the multiple writes once
    // their byte-count byte has arrived.
    if (pdu_prefix.empty()) return PredictedLength{};
    switch (pdu_prefix[0]) {
        case fc::read_coils:
        case fc::read_discrete_inputs:
        case fc::read_holding_registers:
        case fc::read_input_registers:
        case fc::write_single_coil:
        case fc::write_single_register:
            return known_length(address_value_pdu_size);
        case fc::read_exception_status:
            return known_length(read_exception_status_request_size);
        case fc::write_multiple_coils:
        case fc::write_multiple_registers:
            if (pdu_prefix.size() < write_multiple_header_size) return PredictedLength{};
            return known_length(write_multiple_header_size + pdu_prefix[5]);
        case fc::mask_write_register:
            return known_length(mask_write_pdu_size);
        case fc::read_write_multiple_registers:
            if (pdu_prefix.size() < read_write_header_size) return PredictedLength{};
            return known_length(read_write_header_size + pdu_prefix[9]);
        default:
            return std::nullopt;
    }
}

}  // namespace fieldbridge::protocol
