#pragma once
/// @file passed_sockets.hpp
/// Socket activation, the pure part: which `modbus_tcp.listen` entry each socket
/// passed by the service manager serves. The systemd side (reading LISTEN_FDS) is
/// systemd_sockets.hpp; the Modbus TCP server takes the result through
/// ModbusTcpServer::adopt().
///
/// Matching, for each passed socket:
///  1. by address: the entry whose IP and port are the address the socket is bound to;
///  2. otherwise by name: a socket whose FileDescriptorName= is a port number ("502";
///     names cannot hold the ':' of an address) serves the one entry with that port;
/// and then every entry must have a socket. Anything else is an error that says which
/// socket or entry is left over and how to make the socket unit and the
/// configuration agree.
#include <asio/ip/tcp.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "config/net_address.hpp"
#include "core/error.hpp"
#include "northbound/modbus_tcp/listen_socket.hpp"

namespace fieldbridge::daemon {

/// A start-up error of socket activation (a mismatch between the socket unit and the
/// configuration); the process exits with exit_config_error.
class SocketActivationError : public core::Error {
public:
    using core::Error::Error;
};

/// One file descriptor passed by the service manager.
struct PassedSocket {
    int fd = -1;
    std::string name;  ///< FileDescriptorName=, "unknown" when none was given
    /// Where it listens; nullopt when it is not a listening TCP/IP stream socket.
    std::optional<asio::ip::tcp::endpoint> listening;
};

/// The entry each of @p passed serves, in the order of @p listen. Empty when @p passed
/// is empty (not socket-activated: the server binds by itself). Throws
/// SocketActivationError.
[[nodiscard]] std::vector<northbound::modbus_tcp::InheritedListener> match_passed_sockets(
    const std::vector<config::ListenAddress>& listen, const std::vector<PassedSocket>& passed);

}  // namespace fieldbridge::daemon
