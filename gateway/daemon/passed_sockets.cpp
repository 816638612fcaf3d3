#include "daemon/passed_sockets.hpp"

#include <algorithm>
#include <charconv>
#include <fmt/format.h>

namespace fieldbridge::daemon {
namespace {

[[nodiscard]] std::string describe(const PassedSocket& socket) {
    std::string text = fmt::format("fd {} (FileDescriptorName={}", socket.fd, socket.name);
    if (socket.listening) {
        const auto& endpoint = *socket.listening;
        const auto address = endpoint.address();
        text += address.is_v6() ? fmt::format(", listening on [{}]:{})", address.to_string(), endpoint.port())
                                : fmt::format(", listening on {}:{})", address.to_string(), endpoint.port());
    } else {
        text += ")";
    }
    return text;
}

[[nodiscard]] std::string entries(const std::vector<config::ListenAddress>& listen) {
    std::string text;
    for (const auto& address : listen) text += (text.empty() ? "" : ", ") + address.to_string();
    return "[" + text + "]";
}

[[nodiscard]] bool same_address(const config::ListenAddress& entry, const asio::ip::tcp::endpoint& endpoint) {
    asio::error_code error;
    const auto ip = asio::ip::make_address(entry.host, error);
    return !error && ip == endpoint.address() && entry.port == endpoint.port();
}

/// The port a FileDescriptorName= stands for, when it is one.
[[nodiscard]] std::optional<std::uint16_t> named_port(const std::string& name) {
    unsigned value = 0;
    const auto* end = name.data() + name.size();
    const auto [rest, error] = std::from_chars(name.data(), end, value);
    if (name.empty() || error != std::errc{} || rest != end || value == 0 || value > 65535) return std::nullopt;
    return static_cast<std::uint16_t>(value);
}

}  // namespace

std::vector<northbound::modbus_tcp::InheritedListener> match_passed_sockets(
    const std::vector<config::ListenAddress>& listen, const std::vector<PassedSocket>& passed) {
    if (passed.empty()) return {};
    constexpr std::size_t none = static_cast<std::size_t>(-1);
    std::vector<std::size_t> socket_of(listen.size(), none);  // entry -> index in passed
    std::vector<bool> matched(passed.size(), false);
    const auto take = [&](std::size_t entry, std::size_t socket) {
        if (socket_of[entry] != none) {
            throw SocketActivationError(fmt::format(
                "socket activation: two sockets were passed for modbus_tcp.listen entry {}: {} and {}; the socket "
                "unit must have one ListenStream= per entry",
                listen[entry].to_string(), describe(passed[socket_of[entry]]), describe(passed[socket])));
        }
        socket_of[entry] = socket;
        matched[socket] = true;
    };

    for (std::size_t s = 0; s < passed.size(); ++s) {
        if (!passed[s].listening) {
            throw SocketActivationError(fmt::format(
                "socket activation: {} is not a listening TCP/IP socket; the socket unit of fieldbridge may only "
                "have ListenStream= lines with an IP address and port",
                describe(passed[s])));
        }
        for (std::size_t e = 0; e < listen.size(); ++e) {
            if (same_address(listen[e], *passed[s].listening)) take(e, s);
        }
    }
    for (std::size_t s = 0; s < passed.size(); ++s) {
        if (matched[s]) continue;
        const auto port = named_port(passed[s].name);
        std::vector<std::size_t> candidates;  // entries with that port and no socket yet
        std::size_t taken = none;             // one with that port and a socket already
        for (std::size_t e = 0; port && e < listen.size(); ++e) {
            if (listen[e].port != *port) continue;
            if (socket_of[e] == none) {
                candidates.push_back(e);
            } else {
                taken = e;
            }
        }
        if (candidates.size() == 1 || (candidates.empty() && taken != none)) {
            take(candidates.empty() ? taken : candidates.front(), s);  // the latter throws: two sockets
            continue;
        }
        if (candidates.size() > 1) {
            throw SocketActivationError(fmt::format(
                "socket activation: {} names port {}, which more than one modbus_tcp.listen entry without a socket "
                "has ({}); make ListenStream= the entry's exact address instead",
                describe(passed[s]), *port, entries(listen)));
        }
        throw SocketActivationError(fmt::format(
            "socket activation: {} matches no modbus_tcp.listen entry {} by address, nor by FileDescriptorName= "
            "(the port of an entry); make ListenStream= of the socket unit and modbus_tcp.listen agree",
            describe(passed[s]), entries(listen)));
    }

    std::vector<northbound::modbus_tcp::InheritedListener> out;
    for (std::size_t e = 0; e < listen.size(); ++e) {
        if (socket_of[e] == none) {
            throw SocketActivationError(fmt::format(
                "socket activation: modbus_tcp.listen entry {} has no socket, while the service manager passed {}; "
                "add ListenStream={} to the socket unit, or remove the entry",
                listen[e].to_string(), passed.size() == 1 ? std::string("one") : std::to_string(passed.size()),
                listen[e].to_string()));
        }
        out.push_back({listen[e], passed[socket_of[e]].fd});
    }
    return out;
}

}  // namespace fieldbridge::daemon
