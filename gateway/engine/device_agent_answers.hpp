#pragma once
/// @file device_agent_answers.hpp
/// What a northbound client gets when the device agent answers without the
/// profile's respond(): a read served from the register image, and the Modbus
/// exception for a transaction that ended without a reply (spec §4). Pure.

#include <optional>

#include "engine/register_image.hpp"
#include "engine/transaction.hpp"
#include "protocol/gateway_exceptions.hpp"
#include "protocol/modbus_pdu.hpp"

namespace fieldbridge::engine {

/// Spec §4 and §3 rule 9, through the gateway's one mapping
/// (protocol/gateway_exceptions.hpp): timeout / device_offline -> no_answer (0x0B);
/// expired -> expired (0x0B: a command's deadline passed before it could start);
/// queue_full -> busy (0x06); line_down -> path_down (0x0A: nothing was sent, the
/// line is down); cancelled -> cancelled (0x0A: the line or the agent was shut down
/// or reconfigured before the answer came); anything else that is not a reply ->
/// gateway_failure (0x04).
[[nodiscard]] protocol::GatewayRefusal refusal_for(OutcomeStatus status) noexcept;
[[nodiscard]] protocol::ExceptionCode exception_for(OutcomeStatus status) noexcept;

/// An exception under the client's own function code (an XEG FC06 that went out as
/// FC16 fails as FC06).
[[nodiscard]] protocol::Response exception_response(const protocol::Request& request,
                                                    protocol::ExceptionCode code);
[[nodiscard]] protocol::Response exception_response(const protocol::Request& request,
                                                    protocol::GatewayRefusal refusal);

/// The answer to an FC01-04 read from @p image when every register asked for is
/// present, good, and younger than @p max_age (RegisterImage::read_fresh); nullopt
/// otherwise, for writes and for other function codes. The image holds the
/// northbound view (pairs high word first), so no translation is needed.
[[nodiscard]] std::optional<protocol::Response> answer_from_image(const protocol::Request& request,
                                                                  const RegisterImage& image, TimePoint now,
                                                                  Duration max_age);

}  // namespace fieldbridge::engine
