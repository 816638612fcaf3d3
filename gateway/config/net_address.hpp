#pragma once
/// @file net_address.hpp
/// Network values of the configuration: listen addresses (`host:port`,
/// `[v6]:port`) and CIDR networks for the Modbus TCP allow-list and rules.

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "config/parsed.hpp"

namespace fieldbridge::config {

/// An IPv6 address, or an IPv4 address in its IPv4-mapped form (::ffff:a.b.c.d),
/// so that one comparison serves clients on IPv4 and dual-stack sockets alike.
using IpAddress = std::array<std::uint8_t, 16>;

/// IPv4 dotted quad or IPv6 text (no brackets, no zone).
[[nodiscard]] std::optional<IpAddress> parse_ip_address(std::string_view text);
/// @p v4 in host byte order (0x7F000001 is 127.0.0.1).
[[nodiscard]] IpAddress ipv4_mapped(std::uint32_t v4) noexcept;
[[nodiscard]] bool is_ipv4_mapped(const IpAddress& address) noexcept;

/// A host name (RFC 1123 labels) or an IPv4 / IPv6 literal (IPv6 without brackets).
[[nodiscard]] bool is_valid_host(std::string_view host);

/// Where a listener binds: an IP literal and a port.
struct ListenAddress {
    std::string host;        ///< IPv4 or IPv6 literal, IPv6 without brackets
    std::uint16_t port = 0;  ///< 1..65535

    /// "0.0.0.0:502", "[::1]:1502".
    [[nodiscard]] std::string to_string() const;
    [[nodiscard]] bool is_ipv6() const noexcept { return host.find(':') != std::string::npos; }
    bool operator==(const ListenAddress&) const = default;
};

/// "0.0.0.0:502" or "[::1]:1502".
[[nodiscard]] Parsed<ListenAddress> parse_listen_address(std::string_view text);

/// A line's port on a serial device server in transparent mode: `tcp://host:port`.
struct TcpEndpoint {
    std::string host;        ///< host name, IPv4 literal, or IPv6 literal without brackets
    std::uint16_t port = 0;  ///< 1..65535

    /// "192.168.1.20:4001", "[fd00::7]:4001", "nport-3.cell:4001".
    [[nodiscard]] std::string to_string() const;
    bool operator==(const TcpEndpoint&) const = default;
};

/// The scheme that makes a line's `port` a TCP endpoint instead of a device path.
inline constexpr std::string_view tcp_port_scheme = "tcp://";

/// True when @p port starts with `tcp://` (whether the rest is valid or not).
[[nodiscard]] bool is_tcp_port(std::string_view port) noexcept;

/// "tcp://192.168.1.20:4001", "tcp://[fd00::7]:4001", "tcp://nport-3.cell:4001".
[[nodiscard]] Parsed<TcpEndpoint> parse_tcp_port(std::string_view text);

/// A network: `10.0.0.0/8`, `fd00::/8`, or a single address (`192.168.1.5` = /32).
struct Cidr {
    IpAddress network{};         ///< host bits are zero
    unsigned prefix_length = 0;  ///< over the 16-byte form: an IPv4 /n is stored as 96 + n
    std::string text;            ///< as written in the config, for logs

    [[nodiscard]] bool contains(const IpAddress& address) const noexcept;
    bool operator==(const Cidr&) const = default;
};

/// Host bits set below the prefix are an error (`10.1.2.3/8`): the text suggests the
/// network the operator probably meant.
[[nodiscard]] Parsed<Cidr> parse_cidr(std::string_view text);

}  // namespace fieldbridge::config
