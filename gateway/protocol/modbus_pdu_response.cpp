// Modbus PDU codec: responses, exceptions and reply-length prediction. Section
// numbers cite the Modbus Application Protocol Specification V1.1b3.
#include <string>
#include <variant>

#include "protocol/gateway_exceptions.hpp"
#include "protocol/modbus_pdu.hpp"
#include "protocol/modbus_pdu_detail.hpp"

namespace fieldbridge::protocol {

using namespace detail;

namespace {

constexpr const char* response_kind = "response";

using ResponseResult = DecodeResult<Response>;

/// What a normal reply to @p request looks like: its PDU size, and for the reads the
/// byte count it carries (0 otherwise). Sizes follow from the request alone (6.1-6.17).
struct ExpectedReply {
    std::size_t pdu_size = 0;
    std::size_t byte_count = 0;
};

ExpectedReply reads(std::size_t byte_count) {
    return {byte_count_reply_header_size + byte_count, byte_count};
}

/// nullopt for an opaque request: only the device knows.
std::optional<ExpectedReply> expected_reply(const Request& request) {
    return std::visit(
        Overloaded{
            [](const ReadBitsRequest& r) -> std::optional<ExpectedReply> {
                return reads(bit_byte_count(r.count));
            },
            [](const ReadRegistersRequest& r) -> std::optional<ExpectedReply> {
                return reads(2U * r.count);
            },
            [](const ReadWriteRegistersRequest& r) -> std::optional<ExpectedReply> {
                return reads(2U * r.read_count);
            },
            [](const ReadExceptionStatusRequest&) -> std::optional<ExpectedReply> {
                return ExpectedReply{two_byte_pdu_size, 0};
            },
            [](const OpaqueRequest&) -> std::optional<ExpectedReply> { return std::nullopt; },
            [](const MaskWriteRegisterRequest&) -> std::optional<ExpectedReply> {
                return ExpectedReply{mask_write_pdu_size, 0};
            },
            // FC05 / FC06 / FC0F / FC10: address and value or quantity (6.5, 6.6, 6.11, 6.12).
            [](const auto&) -> std::optional<ExpectedReply> {
                return ExpectedReply{address_value_pdu_size, 0};
            },
        },
        request);
}

/// The echo a write reply must carry: address and value (FC05/06) or quantity (FC0F/10).
struct Echo {
    std::uint16_t address = 0;
    std::uint16_t value = 0;
};

std::optional<Echo> expected_echo(const Request& request) {
    return std::visit(
        Overloaded{
            [](const WriteSingleCoilRequest& r) -> std::optional<Echo> {
                return Echo{r.address, r.value ? coil_on : coil_off};
            },
            [](const WriteSingleRegisterRequest& r) -> std::optional<Echo> {
                return Echo{r.address, r.value};
            },
            [](const WriteMultipleCoilsRequest& r) -> std::optional<Echo> {
                return Echo{r.address, static_cast<std::uint16_t>(r.values.size())};
            },
            [](const WriteMultipleRegistersRequest& r) -> std::optional<Echo> {
                return Echo{r.address, static_cast<std::uint16_t>(r.values.size())};
            },
            [](const auto&) -> std::optional<Echo> { return std::nullopt; },
        },
        request);
}

/// A normal (non-exception) reply whose function code already matches the request.
ResponseResult decode_normal(ByteView pdu, const Request& request) {
    const std::size_t size = pdu.size();
    const std::uint8_t function = pdu[0];
    const auto expected = expected_reply(request);
    if (!expected) return ResponseResult::ok(OpaqueResponse{function, Bytes(pdu.begin() + 1, pdu.end())}, size);

    if (expected->byte_count != 0) {
        // Reads: the byte count must describe the PDU (else the frame is broken) and
        // must be what the request asked for (else it answers another request).
        if (size < byte_count_reply_header_size || pdu[1] == 0 ||
            size != byte_count_reply_header_size + pdu[1]) {
            return ResponseResult::bad(DecodeError::bad_length, size);
        }
        if (pdu[1] != expected->byte_count) return ResponseResult::bad(DecodeError::unexpected_reply, size);
        const ByteView data = pdu.subspan(byte_count_reply_header_size);
        if (function == fc::read_coils || function == fc::read_discrete_inputs) {
            // The reply carries whole bytes; the reader knows how many bits it asked.
            return ResponseResult::ok(ReadBitsResponse{function, get_bits(data, 8 * data.size())}, size);
        }
        return ResponseResult::ok(ReadRegistersResponse{function, get_registers(data)}, size);
    }
    if (size != expected->pdu_size) return ResponseResult::bad(DecodeError::bad_length, size);
    if (function == fc::read_exception_status) {
        return ResponseResult::ok(ReadExceptionStatusResponse{pdu[1]}, size);
    }
    if (const auto* mask = std::get_if<MaskWriteRegisterRequest>(&request)) {
        // 6.16: the reply echoes the request.
        const MaskWriteResponse echo{get_u16_be(pdu, 1), get_u16_be(pdu, 3), get_u16_be(pdu, 5)};
        if (echo.address != mask->address || echo.and_mask != mask->and_mask || echo.or_mask != mask->or_mask) {
            return ResponseResult::bad(DecodeError::unexpected_reply, size);
        }
        return ResponseResult::ok(echo, size);
    }
    const Echo echo{get_u16_be(pdu, 1), get_u16_be(pdu, 3)};
    const auto want = expected_echo(request);
    if (!want || echo.address != want->address || echo.value != want->value) {
        return ResponseResult::bad(DecodeError::unexpected_reply, size);
    }
    if (function == fc::write_single_coil || function == fc::write_single_register) {
        return ResponseResult::ok(WriteSingleResponse{function, echo.address, echo.value}, size);
    }
    return ResponseResult::ok(WriteMultipleResponse{function, echo.address, echo.value}, size);
}

void check_function(std::uint8_t function, std::uint8_t first, std::uint8_t second) {
    if (function != first && function != second) {
        reject(function, response_kind,
               "function code must be " + function_name(first) + " or " + function_name(second));
    }
}

}  // namespace

Bytes encode_response(const Response& response) {
    Bytes out;
    std::visit(
        Overloaded{
            [&out](const ReadBitsResponse& r) {
                check_function(r.function, fc::read_coils, fc::read_discrete_inputs);
                check_quantity(r.function, response_kind, "bit count", r.bits.size(), max_read_bits);
                out.push_back(r.function);
                out.push_back(static_cast<std::uint8_t>(bit_byte_count(r.bits.size())));
                put_bits(out, r.bits);
            },
            [&out](const ReadRegistersResponse& r) {
                if (r.function != fc::read_write_multiple_registers) {
                    check_function(r.function, fc::read_holding_registers, fc::read_input_registers);
                }
                check_quantity(r.function, response_kind, "register count", r.values.size(),
                               max_read_registers);
                out.push_back(r.function);
                out.push_back(static_cast<std::uint8_t>(2 * r.values.size()));
                put_registers(out, r.values);
            },
            [&out](const WriteSingleResponse& r) {
                check_function(r.function, fc::write_single_coil, fc::write_single_register);
                out.push_back(r.function);
                put_u16_be(out, r.address);
                put_u16_be(out, r.value);
            },
            [&out](const ReadExceptionStatusResponse& r) {
                out.push_back(fc::read_exception_status);
                out.push_back(r.status);
            },
            [&out](const WriteMultipleResponse& r) {
                check_function(r.function, fc::write_multiple_coils, fc::write_multiple_registers);
                out.push_back(r.function);
                put_u16_be(out, r.address);
                put_u16_be(out, r.count);
            },
            [&out](const MaskWriteResponse& r) {
                out.push_back(fc::mask_write_register);
                put_u16_be(out, r.address);
                put_u16_be(out, r.and_mask);
                put_u16_be(out, r.or_mask);
            },
            [&out](const ExceptionResponse& r) { out = encode_exception(r.function, r.code); },
            [&out](const OpaqueResponse& r) {
                if (r.function == 0 || (r.function & fc::exception_flag) != 0) {
                    reject(r.function, response_kind, "function code must be 1..127");
                }
                if (r.data.size() > max_pdu_size - 1) {
                    reject(r.function, response_kind,
                           std::to_string(r.data.size()) + " data bytes exceed the " +
                               std::to_string(max_pdu_size - 1) + " a PDU can carry");
                }
                out.push_back(r.function);
                out.insert(out.end(), r.data.begin(), r.data.end());
            },
        },
        response);
    return out;
}

Bytes encode_exception(std::uint8_t function, ExceptionCode code) {
    if (function == 0 || (function & fc::exception_flag) != 0) {
        reject(function, "exception", "function code must be 1..127 (without the 0x80 flag)");
    }
    return exception_pdu(core::FunctionCode{function}, code);
}

DecodeResult<Response> decode_response(ByteView pdu, const Request& request) {
    const std::size_t size = pdu.size();
    if (size == 0) return ResponseResult::bad(DecodeError::bad_length, 0);
    if (size > max_pdu_size) return ResponseResult::bad(DecodeError::oversize, size);
    const std::uint8_t function = function_of(request);
    if (pdu[0] == static_cast<std::uint8_t>(function | fc::exception_flag)) {
        if (size != two_byte_pdu_size) return ResponseResult::bad(DecodeError::bad_length, size);
        // Any exception code is carried as-is, so a gateway passes device-specific
        // codes through unchanged.
        return ResponseResult::ok(ExceptionResponse{function, static_cast<ExceptionCode>(pdu[1])}, size);
    }
    if (pdu[0] != function) return ResponseResult::bad(DecodeError::wrong_function, size);
    return decode_normal(pdu, request);
}

std::optional<PredictedLength> predict_response_pdu_length(ByteView pdu_prefix,
                                                           const Request& request) {
    if (pdu_prefix.empty()) return PredictedLength{};
    const std::uint8_t function = function_of(request);
    if (pdu_prefix[0] == static_cast<std::uint8_t>(function | fc::exception_flag)) {
        return PredictedLength{DecodeStatus::complete, two_byte_pdu_size};
    }
    if (pdu_prefix[0] != function) return PredictedLength{DecodeStatus::malformed, 0};
    const auto expected = expected_reply(request);
    if (!expected) return std::nullopt;
    return PredictedLength{DecodeStatus::complete, expected->pdu_size};
}

}  // namespace fieldbridge::protocol
