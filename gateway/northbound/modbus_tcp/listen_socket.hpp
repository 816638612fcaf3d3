#pragma once
/// @file listen_socket.hpp
/// Opening the listening sockets of the Modbus TCP server, with errors that say what
/// to do (port taken, privileged port, address not on this machine), taking over
/// sockets that are already listening (socket activation), and the conversions between asio's addresses and the configuration's.
#include <asio/io_context.hpp>
#include <asio/ip/tcp.hpp>
#include <string>

#include "config/config.hpp"

namespace fieldbridge::northbound::modbus_tcp {

/// The steps of opening a listening socket on @p endpoint (open, SO_REUSEADDR,
/// IPV6_V6ONLY = @p v6_only for IPv6, bind, listen) on @p acceptor. Returns the first
/// error, with @p step naming the step that failed ("open", "bind", "listen").
[[nodiscard]] asio::error_code bind_and_listen(asio::ip::tcp::acceptor& acceptor,
                                               const asio::ip::tcp::endpoint& endpoint, bool v6_only,
                                               const char*& step);

/// Binds and listens on @p address. @p v6_only applies to IPv6 addresses: set it when
/// an IPv4 listener shares the port, so that both can bind. Throws ModbusTcpError.
[[nodiscard]] asio::ip::tcp::acceptor open_listen_socket(asio::io_context& io, const config::ListenAddress& address,
                                                         bool v6_only);

/// A listening TCP socket the process was given (systemd socket activation) for
/// @p address of modbus_tcp.listen. Whoever holds it owns @p fd.
struct InheritedListener {
    config::ListenAddress address;
    int fd = -1;
};

/// A new acceptor on a duplicate of the listening socket @p fd (close-on-exec); @p fd
/// itself stays open and owned by the caller, so closing the acceptor leaves the socket
/// listening. Throws ModbusTcpError when @p fd is not a TCP socket or cannot be
/// duplicated.
[[nodiscard]] asio::ip::tcp::acceptor duplicate_listen_socket(asio::io_context& io, int fd,
                                                              const config::ListenAddress& address);

/// What the operator can do about a failed bind/listen of @p address.
[[nodiscard]] std::string listen_advice(const asio::error_code& error, const config::ListenAddress& address);

/// The configuration's form of a client address (IPv4 as IPv4-mapped IPv6).
[[nodiscard]] config::IpAddress to_ip_address(const asio::ip::address& address);

/// "192.168.1.5:50312", "[fd00::5]:50312".
[[nodiscard]] std::string to_string(const asio::ip::tcp::endpoint& endpoint);

}  // namespace fieldbridge::northbound::modbus_tcp
