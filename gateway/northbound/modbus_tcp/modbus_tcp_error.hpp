#pragma once
/// @file modbus_tcp_error.hpp
/// The start-up error of the Modbus TCP server (a listener that cannot be opened).
/// Per-request outcomes are never exceptions: they are Modbus exception responses.
#include <stdexcept>

#include "core/error.hpp"

namespace fieldbridge::northbound::modbus_tcp {

class ModbusTcpError : public core::Error {
public:
    using core::Error::Error;
};

}  // namespace fieldbridge::northbound::modbus_tcp
