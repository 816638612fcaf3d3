#pragma once
/// @file listen_socket.hpp
/// Opening the listening sockets of the Modbus TCP server, with errors that say what
/// to do (port taken, privileged port, address not on this machine), and the
/// conversions between asio's addresses and the configuration's.
#include <asio/io_context.hpp>
#include <asio/ip/tcp.hpp>
#include <string>

#include "config/config.hpp"

namespace fieldbridge::northbound::modbus_tcp {

/// Binds and listens on @p address. @p v6_only applies to IPv6 addresses: set it when
/// an IPv4 listener shares the port, so that both can bind. Throws ModbusTcpError.
[[nodiscard]] asio::ip::tcp::acceptor open_listen_socket(asio::io_context& io, const config::ListenAddress& address,
                                                         bool v6_only);

/// What the operator can do about a failed bind/listen of @p address.
[[nodiscard]] std::string listen_advice(const asio::error_code& error, const config::ListenAddress& address);

/// The configuration's form of a client address (IPv4 as IPv4-mapped IPv6).
[[nodiscard]] config::IpAddress to_ip_address(const asio::ip::address& address);

/// "192.168.1.5:50312", "[fd00::5]:50312".
[[nodiscard]] std::string to_string(const asio::ip::tcp::endpoint& endpoint);

}  // namespace fieldbridge::northbound::modbus_tcp
