#pragma once
/// @file modbus_pdu.hpp
/// Modbus PDU (function code + data) codec, shared by RTU and MBAP framing.
/// Pure functions over bytes: no I/O, no state. Function codes the gateway does not
/// interpret are carried opaquely so pass-through stays transparent.

#include <cstdint>
#include <optional>
#include <variant>
#include <vector>

#include "core/modbus_ids.hpp"
#include "protocol/bytes.hpp"
#include "protocol/decode_result.hpp"

namespace fieldbridge::protocol {

/// The function codes the codec knows, typed: what the gateway compares and decides on
/// (core::FunctionCode, docs/architecture.md "One definition per concept").
namespace fn {
inline constexpr core::FunctionCode read_coils{0x01};
inline constexpr core::FunctionCode read_discrete_inputs{0x02};
inline constexpr core::FunctionCode read_holding_registers{0x03};
inline constexpr core::FunctionCode read_input_registers{0x04};
inline constexpr core::FunctionCode write_single_coil{0x05};
inline constexpr core::FunctionCode write_single_register{0x06};
inline constexpr core::FunctionCode read_exception_status{0x07};
inline constexpr core::FunctionCode write_multiple_coils{0x0F};
inline constexpr core::FunctionCode write_multiple_registers{0x10};
inline constexpr core::FunctionCode report_server_id{0x11};
inline constexpr core::FunctionCode mask_write_register{0x16};
inline constexpr core::FunctionCode read_write_multiple_registers{0x17};
}  // namespace fn

/// The same codes as the bytes of the wire: the codec's structs and byte layout, and the
/// simulators, which build PDUs byte by byte. Gateway code decides on fn:: instead.
namespace fc {
inline constexpr std::uint8_t read_coils = fn::read_coils.value;
inline constexpr std::uint8_t read_discrete_inputs = fn::read_discrete_inputs.value;
inline constexpr std::uint8_t read_holding_registers = fn::read_holding_registers.value;
inline constexpr std::uint8_t read_input_registers = fn::read_input_registers.value;
inline constexpr std::uint8_t write_single_coil = fn::write_single_coil.value;
inline constexpr std::uint8_t write_single_register = fn::write_single_register.value;
inline constexpr std::uint8_t read_exception_status = fn::read_exception_status.value;
inline constexpr std::uint8_t write_multiple_coils = fn::write_multiple_coils.value;
inline constexpr std::uint8_t write_multiple_registers = fn::write_multiple_registers.value;
inline constexpr std::uint8_t report_server_id = fn::report_server_id.value;
inline constexpr std::uint8_t mask_write_register = fn::mask_write_register.value;
inline constexpr std::uint8_t read_write_multiple_registers = fn::read_write_multiple_registers.value;
/// Bit 7 of the function byte: set in an exception reply (section 7).
inline constexpr std::uint8_t exception_flag = 0x80;
}  // namespace fc

/// Modbus exception codes (Modbus Application Protocol V1.1b3, section 7).
enum class ExceptionCode : std::uint8_t {
    illegal_function = 0x01,
    illegal_data_address = 0x02,
    illegal_data_value = 0x03,
    server_device_failure = 0x04,
    acknowledge = 0x05,
    server_device_busy = 0x06,
    memory_parity_error = 0x08,
    gateway_path_unavailable = 0x0A,
    gateway_target_failed = 0x0B,
};

/// Protocol limits (Modbus Application Protocol V1.1b3, section 6).
inline constexpr std::uint16_t max_read_bits = 2000;
inline constexpr std::uint16_t max_read_registers = 125;
inline constexpr std::uint16_t max_write_coils = 1968;
inline constexpr std::uint16_t max_write_registers = 123;
inline constexpr std::uint16_t max_rw_write_registers = 121;
inline constexpr std::size_t max_pdu_size = 253;

// ---- requests -------------------------------------------------------------------

/// FC01 / FC02.
struct ReadBitsRequest {
    std::uint8_t function = fc::read_coils;
    std::uint16_t address = 0;
    std::uint16_t count = 0;
    bool operator==(const ReadBitsRequest&) const = default;
};
/// FC03 / FC04.
struct ReadRegistersRequest {
    std::uint8_t function = fc::read_holding_registers;
    std::uint16_t address = 0;
    std::uint16_t count = 0;
    bool operator==(const ReadRegistersRequest&) const = default;
};
/// FC05. On the wire ON is 0xFF00 and OFF 0x0000; any other value is malformed.
struct WriteSingleCoilRequest {
    std::uint16_t address = 0;
    bool value = false;
    bool operator==(const WriteSingleCoilRequest&) const = default;
};
/// FC06.
struct WriteSingleRegisterRequest {
    std::uint16_t address = 0;
    std::uint16_t value = 0;
    bool operator==(const WriteSingleRegisterRequest&) const = default;
};
/// FC07 (no data).
struct ReadExceptionStatusRequest {
    bool operator==(const ReadExceptionStatusRequest&) const = default;
};
/// FC0F.
struct WriteMultipleCoilsRequest {
    std::uint16_t address = 0;
    std::vector<bool> values;
    bool operator==(const WriteMultipleCoilsRequest&) const = default;
};
/// FC10.
struct WriteMultipleRegistersRequest {
    std::uint16_t address = 0;
    std::vector<std::uint16_t> values;
    bool operator==(const WriteMultipleRegistersRequest&) const = default;
};
/// FC16 (mask write register): the register becomes (current AND and_mask) OR (or_mask AND NOT and_mask)
/// (Modbus Application Protocol 6.16).
struct MaskWriteRegisterRequest {
    std::uint16_t address = 0;
    std::uint16_t and_mask = 0;
    std::uint16_t or_mask = 0;
    bool operator==(const MaskWriteRegisterRequest&) const = default;
    /// What the register holds after the write, from what it held before.
    [[nodiscard]] constexpr std::uint16_t applied_to(std::uint16_t current) const noexcept {
        return static_cast<std::uint16_t>((current & and_mask) | (or_mask & ~and_mask));
    }
};
/// FC17 (read/write multiple registers): the write is performed before the read.
struct ReadWriteRegistersRequest {
    std::uint16_t read_address = 0;
    std::uint16_t read_count = 0;
    std::uint16_t write_address = 0;
    std::vector<std::uint16_t> values;
    bool operator==(const ReadWriteRegistersRequest&) const = default;
};
/// Any other function code: data carried as-is.
struct OpaqueRequest {
    std::uint8_t function = 0;
    Bytes data;
    bool operator==(const OpaqueRequest&) const = default;
};

using Request = std::variant<ReadBitsRequest, ReadRegistersRequest, WriteSingleCoilRequest,
                             WriteSingleRegisterRequest, ReadExceptionStatusRequest,
                             WriteMultipleCoilsRequest, WriteMultipleRegistersRequest,
                             MaskWriteRegisterRequest, ReadWriteRegistersRequest, OpaqueRequest>;

// ---- responses ------------------------------------------------------------------

/// FC01 / FC02: the bits as sent (byte_count * 8); the reader knows how many it asked.
struct ReadBitsResponse {
    std::uint8_t function = fc::read_coils;
    std::vector<bool> bits;
    bool operator==(const ReadBitsResponse&) const = default;
};
/// FC03 / FC04 / FC17.
struct ReadRegistersResponse {
    std::uint8_t function = fc::read_holding_registers;
    std::vector<std::uint16_t> values;
    bool operator==(const ReadRegistersResponse&) const = default;
};
/// FC05 / FC06: echo of address and value.
struct WriteSingleResponse {
    std::uint8_t function = fc::write_single_register;
    std::uint16_t address = 0;
    std::uint16_t value = 0;
    bool operator==(const WriteSingleResponse&) const = default;
};
/// FC07.
struct ReadExceptionStatusResponse {
    std::uint8_t status = 0;
    bool operator==(const ReadExceptionStatusResponse&) const = default;
};
/// FC0F / FC10: address and quantity written.
struct WriteMultipleResponse {
    std::uint8_t function = fc::write_multiple_registers;
    std::uint16_t address = 0;
    std::uint16_t count = 0;
    bool operator==(const WriteMultipleResponse&) const = default;
};
/// FC16 (mask write register): the echo of the request (6.16).
struct MaskWriteResponse {
    std::uint16_t address = 0;
    std::uint16_t and_mask = 0;
    std::uint16_t or_mask = 0;
    bool operator==(const MaskWriteResponse&) const = default;
};
/// Function code with 0x80 set; `function` holds the code without the flag.
struct ExceptionResponse {
    std::uint8_t function = 0;
    ExceptionCode code = ExceptionCode::illegal_function;
    bool operator==(const ExceptionResponse&) const = default;
};
struct OpaqueResponse {
    std::uint8_t function = 0;
    Bytes data;
    bool operator==(const OpaqueResponse&) const = default;
};

using Response = std::variant<ReadBitsResponse, ReadRegistersResponse, WriteSingleResponse,
                              ReadExceptionStatusResponse, WriteMultipleResponse, MaskWriteResponse,
                              ExceptionResponse, OpaqueResponse>;

// ---- codec ----------------------------------------------------------------------

/// The function byte of a request as the codec lays it out (the codec and the
/// simulators); the gateway decides on function_code().
[[nodiscard]] std::uint8_t function_of(const Request& request) noexcept;

/// The function code of a decoded request, typed.
[[nodiscard]] core::FunctionCode function_code(const Request& request) noexcept;

/// The function code of one decoded PDU struct (ReadRegistersRequest, ExceptionResponse,
/// ...), typed: their `function` fields stay the wire's byte.
template <class Pdu>
    requires requires(const Pdu& pdu) { std::uint8_t{pdu.function}; }
[[nodiscard]] constexpr core::FunctionCode function_code(const Pdu& pdu) noexcept {
    return core::FunctionCode{pdu.function};
}

/// The function code a raw PDU starts with, as it came (0 .. 0xFF, is_function_code()
/// tells whether it is one); FunctionCode{0} for an empty PDU, which is answered 0x80.
[[nodiscard]] core::FunctionCode pdu_function(ByteView pdu) noexcept;

/// False only for the function codes the Modbus specification defines as reads
/// (01, 02, 03, 04, 07, 0B, 0C, 11, 14, 18, 2B); every other code, unknown ones
/// included, may change the device and counts as a write (never auto-retried).
/// The exception flag 0x80 is ignored.
[[nodiscard]] bool is_write(core::FunctionCode function) noexcept;

/// Encodes a request PDU. Throws core::InvalidArgument when the request breaks a
/// protocol limit (count 0 or above the maximum, empty write): callers validate first.
[[nodiscard]] Bytes encode_request(const Request& request);

/// Decodes one complete request PDU (exact length). A PDU shorter or longer than
/// its function code implies, a count of 0 or above the limit, a byte count that
/// disagrees with the count: malformed (bad_length / bad_value).
/// Exact-length decoder: never need_more; on malformed, `consumed` is the whole input.
/// bad_length: empty, or size / byte count inconsistent; oversize: above max_pdu_size;
/// bad_value: function code 0 or >= 0x80, quantity 0 or above the limit, FC05 value
/// other than 0xFF00 / 0x0000. Unknown function codes decode as OpaqueRequest.
[[nodiscard]] DecodeResult<Request> decode_request(ByteView pdu);

/// Encodes a response PDU. Throws core::InvalidArgument for a response no device
/// may send (function code that does not fit the type, 0 or above the limit values).
[[nodiscard]] Bytes encode_response(const Response& response);
/// {function | 0x80, code}. Throws core::InvalidArgument unless function is 1..127.
[[nodiscard]] Bytes encode_exception(std::uint8_t function, ExceptionCode code);

/// Decodes one complete response PDU (exact length) in answer to @p request: the
/// function must match (or be the exception of it), the sizes must match what was
/// asked (register count, echo of the write). Exact-length decoder: never need_more;
/// on malformed, `consumed` is the whole input. Errors:
/// - wrong_function: neither the request's function code nor its exception;
/// - bad_length: empty, size inconsistent with the function or its own byte count
///   (a read reply with byte count 0 included); oversize: above max_pdu_size;
/// - unexpected_reply: well formed, but another quantity or another write echo.
/// Read replies decode to ReadBitsResponse (byte_count * 8 bits) or
/// ReadRegistersResponse; FC07 to ReadExceptionStatusResponse; exceptions (any code
/// byte, carried as-is) to ExceptionResponse; replies to opaque requests to OpaqueResponse.
[[nodiscard]] DecodeResult<Response> decode_response(ByteView pdu, const Request& request);

/// Length of the request PDU starting at pdu[0] (the function code), predicted from
/// the function code and, for variable-length requests, the byte-count field
/// (libmodbus' compute_meta_length_after_function / compute_data_length_after_meta).
/// need_more until enough header bytes are there; nullopt for unknown function codes.
struct PredictedLength {
    DecodeStatus status = DecodeStatus::need_more;  ///< complete: `length` is known
    std::size_t length = 0;
};
[[nodiscard]] std::optional<PredictedLength> predict_request_pdu_length(ByteView pdu_prefix);

/// Length of the response PDU to @p request starting at pdu[0]: an exception is
/// always 2 bytes; a normal reply's length is known from the request (reads: byte
/// count from the requested quantity; writes: fixed). need_more for an empty prefix;
/// status malformed when pdu[0] is neither the request's function code nor its
/// exception; nullopt for a normal reply to an opaque request (only the device knows).
[[nodiscard]] std::optional<PredictedLength> predict_response_pdu_length(ByteView pdu_prefix,
                                                                        const Request& request);

}  // namespace fieldbridge::protocol
