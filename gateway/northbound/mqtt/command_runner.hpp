#pragma once
/// @file command_runner.hpp
/// Executes a parsed command on a device source (spec §6): every request is
/// validated by the device's profile first, so a command with one bad value sends
/// nothing; then the requests go through the device's command lane one after
/// another, each after the previous one was acknowledged, and the first that fails
/// ends the command (the earlier ones were executed: the result says so).
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <asio/io_context.hpp>

#include "northbound/mqtt/device_source.hpp"
#include "northbound/mqtt/payloads.hpp"
#include "protocol/modbus_pdu.hpp"

namespace fieldbridge::northbound::mqtt {

/// "FC16 <address, 4 hex digits> x<count>" (for messages).
[[nodiscard]] std::string describe(const protocol::Request& request);

/// The outcome of a response that ends with a Modbus exception (the error kinds of
/// docs/mqtt.md); ok for a normal response. @p device_type ("wtec-ascii", ...) tells
/// what a 0x04 means: for the WTEC ASCII view a command the gripper did not execute.
[[nodiscard]] CommandOutcome outcome_of(const protocol::Response& response, std::string_view device_type);

/// @p done is called exactly once, on the loop thread, never inside run_command().
/// The source is kept alive until then.
void run_command(asio::io_context& io, std::shared_ptr<DeviceSource> source,
                 std::vector<protocol::Request> requests, std::function<void(CommandOutcome)> done);

}  // namespace fieldbridge::northbound::mqtt
