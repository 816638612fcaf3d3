#pragma once
/// @file device_agent_answers.hpp
/// What a northbound client gets when the device agent answers without the
/// profile's respond(): a read served from the register image, and the Modbus
/// exception for a transaction that ended without a reply (spec §4). Pure.

#include <optional>

#include "engine/register_image.hpp"
#include "engine/transaction.hpp"
#include "protocol/modbus_pdu.hpp"

namespace fieldbridge::engine {

/// Spec §4 and §3 rule 9: timeout / device_offline / line_down / expired -> 0x0B
/// (gateway target failed to respond: the device did not answer, or a command's
/// deadline passed before it could start); queue_full -> 0x06 (server busy: that
/// device's queue is full); cancelled / invalid_request (and anything else that is
/// not a reply) -> 0x04 (server failure: the gateway gave up on it).
[[nodiscard]] protocol::ExceptionCode exception_for(OutcomeStatus status) noexcept;

/// An exception under the client's own function code (an XEG FC06 that went out as
/// FC16 fails as FC06).
[[nodiscard]] protocol::Response exception_response(const protocol::Request& request,
                                                    protocol::ExceptionCode code);

/// The answer to an FC01-04 read from @p image when every register asked for is
/// present, good, and younger than @p max_age (RegisterImage::read_fresh); nullopt
/// otherwise, for writes and for other function codes. The image holds the
/// northbound view (pairs high word first), so no translation is needed.
[[nodiscard]] std::optional<protocol::Response> answer_from_image(const protocol::Request& request,
                                                                  const RegisterImage& image, TimePoint now,
                                                                  Duration max_age);

}  // namespace fieldbridge::engine
