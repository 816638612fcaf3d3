#include "northbound/modbus_tcp/listen_socket.hpp"

#include <asio/ip/v6_only.hpp>
#include <cerrno>
#include <fcntl.h>
#include <fmt/format.h>
#include <sys/socket.h>
#include <system_error>
#include <unistd.h>

#include "northbound/modbus_tcp/modbus_tcp_error.hpp"

namespace fieldbridge::northbound::modbus_tcp {

/// Ports below this need privileges on Linux (net.ipv4.ip_unprivileged_port_start).
constexpr std::uint16_t first_unprivileged_port = 1024;

std::string listen_advice(const asio::error_code& error, const config::ListenAddress& address) {
    if (error == asio::error::address_in_use) {
        return fmt::format("another process listens on port {} (see `ss -ltnp 'sport = :{}'`), or another "
                           "modbus_tcp.listen entry overlaps it; stop that process or choose another port",
                           address.port, address.port);
    }
    if (error == asio::error::access_denied || error.value() == EACCES || error.value() == EPERM) {
        if (address.port < first_unprivileged_port) {
            return fmt::format("port {} is privileged: start fieldbridge from its socket unit (fieldbridge.socket "
                               "with ListenStream={}), run it with CAP_NET_BIND_SERVICE, or listen on a port from "
                               "1024 up (docs/service.md, \"Socket activation\")",
                               address.port, address.to_string());
        }
        return "the system refused the bind (a security policy?); check the journal for an LSM denial";
    }
    if (error.value() == EADDRNOTAVAIL) {
        return fmt::format("{} is not an address of this machine; use one of its interface addresses, or 0.0.0.0 "
                           "/ :: for all",
                           address.host);
    }
    if (error == asio::error::address_family_not_supported) {
        return "IPv6 is disabled on this machine; listen on an IPv4 address";
    }
    return "check modbus_tcp.listen";
}

asio::error_code bind_and_listen(asio::ip::tcp::acceptor& acceptor, const asio::ip::tcp::endpoint& endpoint,
                                 bool v6_only, const char*& step) {
    asio::error_code error;
    step = "open";
    acceptor.open(endpoint.protocol(), error);
    if (!error) {
        // A restarted gateway must rebind at once despite connections in TIME_WAIT.
        acceptor.set_option(asio::ip::tcp::acceptor::reuse_address(true), error);
    }
    if (!error && endpoint.address().is_v6()) acceptor.set_option(asio::ip::v6_only(v6_only), error);
    if (!error) {
        step = "bind";
        acceptor.bind(endpoint, error);
    }
    if (!error) {
        step = "listen";
        acceptor.listen(asio::socket_base::max_listen_connections, error);
    }
    return error;
}

asio::ip::tcp::acceptor open_listen_socket(asio::io_context& io, const config::ListenAddress& address, bool v6_only) {
    asio::error_code error;
    const auto ip = asio::ip::make_address(address.host, error);
    if (error) {
        throw ModbusTcpError(fmt::format("Modbus TCP: cannot listen on {}: {} is not an IP address",
                                         address.to_string(), address.host));
    }
    asio::ip::tcp::acceptor acceptor(io);
    const char* step = "open";
    error = bind_and_listen(acceptor, asio::ip::tcp::endpoint(ip, address.port), v6_only, step);
    if (error) {
        throw ModbusTcpError(fmt::format("Modbus TCP: cannot listen on {} ({} failed: {}): {}", address.to_string(),
                                         step, error.message(), listen_advice(error, address)));
    }
    return acceptor;
}

asio::ip::tcp::acceptor duplicate_listen_socket(asio::io_context& io, int fd, const config::ListenAddress& address) {
    sockaddr_storage local{};
    socklen_t length = sizeof local;
    if (::getsockname(fd, reinterpret_cast<sockaddr*>(&local), &length) != 0 ||
        (local.ss_family != AF_INET && local.ss_family != AF_INET6)) {
        throw ModbusTcpError(fmt::format("Modbus TCP: cannot listen on {}: the socket passed for it (fd {}) is not an "
                                         "IP socket",
                                         address.to_string(), fd));
    }
    const int copy = ::fcntl(fd, F_DUPFD_CLOEXEC, 3);
    if (copy < 0) {
        throw ModbusTcpError(fmt::format("Modbus TCP: cannot listen on {}: duplicating the passed socket (fd {}) "
                                         "failed: {}; raise LimitNOFILE",
                                         address.to_string(), fd, std::generic_category().message(errno)));
    }
    asio::ip::tcp::acceptor acceptor(io);
    asio::error_code error;
    acceptor.assign(local.ss_family == AF_INET6 ? asio::ip::tcp::v6() : asio::ip::tcp::v4(), copy, error);
    if (error) {
        ::close(copy);
        throw ModbusTcpError(fmt::format("Modbus TCP: cannot listen on {} with the passed socket (fd {}): {}",
                                         address.to_string(), fd, error.message()));
    }
    return acceptor;
}

config::IpAddress to_ip_address(const asio::ip::address& address) {
    if (address.is_v4()) return config::ipv4_mapped(address.to_v4().to_uint());
    const auto bytes = address.to_v6().to_bytes();
    config::IpAddress out{};
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = bytes[i];
    return out;
}

std::string to_string(const asio::ip::tcp::endpoint& endpoint) {
    const auto address = endpoint.address();
    if (address.is_v6()) return fmt::format("[{}]:{}", address.to_string(), endpoint.port());
    return fmt::format("{}:{}", address.to_string(), endpoint.port());
}

}  // namespace fieldbridge::northbound::modbus_tcp
