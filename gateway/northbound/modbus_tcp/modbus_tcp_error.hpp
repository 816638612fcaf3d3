#pragma once
/// @file modbus_tcp_error.hpp
/// The start-up error of the Modbus TCP server (a listener that cannot be opened).
/// Per-request outcomes are never exceptions: they are Modbus exception responses.
#include <stdexcept>

namespace fieldbridge::northbound::modbus_tcp {

class ModbusTcpError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

}  // namespace fieldbridge::northbound::modbus_tcp
