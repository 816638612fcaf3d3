#include "daemon/systemd_sockets.hpp"

#include <fmt/format.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <systemd/sd-daemon.h>

#include <cstdlib>
#include <system_error>

namespace fieldbridge::daemon {
namespace {

/// The address @p fd listens on, when it is a listening TCP/IP stream socket.
[[nodiscard]] std::optional<asio::ip::tcp::endpoint> listening_endpoint(int fd) {
    if (sd_is_socket_inet(fd, AF_UNSPEC, SOCK_STREAM, 1, 0) <= 0) return std::nullopt;
    sockaddr_storage local{};
    socklen_t length = sizeof local;
    if (::getsockname(fd, reinterpret_cast<sockaddr*>(&local), &length) != 0) return std::nullopt;
    if (local.ss_family == AF_INET) {
        const auto& v4 = reinterpret_cast<const sockaddr_in&>(local);
        return asio::ip::tcp::endpoint(asio::ip::address_v4(ntohl(v4.sin_addr.s_addr)), ntohs(v4.sin_port));
    }
    const auto& v6 = reinterpret_cast<const sockaddr_in6&>(local);
    asio::ip::address_v6::bytes_type bytes{};
    for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = v6.sin6_addr.s6_addr[i];
    return asio::ip::tcp::endpoint(asio::ip::address_v6(bytes, v6.sin6_scope_id), ntohs(v6.sin6_port));
}

}  // namespace

std::vector<PassedSocket> take_systemd_sockets() {
    char** names = nullptr;
    // unset_environment = 1: nothing this process starts inherits them.
    const int count = sd_listen_fds_with_names(1, &names);
    if (count < 0) {
        throw SocketActivationError(fmt::format("socket activation: LISTEN_FDS / LISTEN_FDNAMES cannot be used: {}; "
                                                "start fieldbridge from its socket unit or without those variables",
                                                std::generic_category().message(-count)));
    }
    std::vector<PassedSocket> passed;
    for (int i = 0; i < count; ++i) {
        const int fd = SD_LISTEN_FDS_START + i;
        passed.push_back(PassedSocket{fd, names != nullptr && names[i] != nullptr ? names[i] : "unknown",
                                      listening_endpoint(fd)});
    }
    if (names != nullptr) {
        for (int i = 0; names[i] != nullptr; ++i) std::free(names[i]);
        std::free(names);
    }
    return passed;
}

}  // namespace fieldbridge::daemon
