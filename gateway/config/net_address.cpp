#include "config/net_address.hpp"

#include <arpa/inet.h>

#include <algorithm>
#include <charconv>
#include <cstring>
#include <utility>

namespace fieldbridge::config {

namespace {

constexpr unsigned ipv4_mapped_prefix = 96;  // ::ffff:0:0/96 (RFC 4291 section 2.5.5.2)

[[nodiscard]] std::optional<IpAddress> parse_ipv4(std::string_view text) {
    const std::string s(text);
    in_addr v4{};
    if (inet_pton(AF_INET, s.c_str(), &v4) != 1) {
        return std::nullopt;
    }
    std::uint32_t host_order = ntohl(v4.s_addr);
    return ipv4_mapped(host_order);
}

[[nodiscard]] std::optional<IpAddress> parse_ipv6(std::string_view text) {
    const std::string s(text);
    in6_addr v6{};
    if (inet_pton(AF_INET6, s.c_str(), &v6) != 1) {
        return std::nullopt;
    }
    IpAddress out{};
    std::memcpy(out.data(), v6.s6_addr, out.size());
    return out;
}

[[nodiscard]] std::string format_ip(const IpAddress& address) {
    char buffer[INET6_ADDRSTRLEN] = {};
    if (is_ipv4_mapped(address)) {
        in_addr v4{};
        std::memcpy(&v4.s_addr, address.data() + 12, 4);
        return inet_ntop(AF_INET, &v4, buffer, sizeof buffer) != nullptr ? std::string(buffer) : std::string();
    }
    in6_addr v6{};
    std::memcpy(v6.s6_addr, address.data(), address.size());
    return inet_ntop(AF_INET6, &v6, buffer, sizeof buffer) != nullptr ? std::string(buffer) : std::string();
}

[[nodiscard]] IpAddress masked(const IpAddress& address, unsigned prefix_length) noexcept {
    IpAddress out{};
    for (std::size_t i = 0; i < out.size(); ++i) {
        const unsigned bit0 = static_cast<unsigned>(i) * 8U;
        if (prefix_length >= bit0 + 8U) {
            out[i] = address[i];
        } else if (prefix_length > bit0) {
            const unsigned keep = prefix_length - bit0;
            out[i] = static_cast<std::uint8_t>(address[i] & static_cast<std::uint8_t>(0xFFU << (8U - keep)));
        }
    }
    return out;
}

[[nodiscard]] std::optional<std::uint16_t> parse_port(std::string_view text) {
    unsigned value = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (text.empty() || ec != std::errc{} || end != text.data() + text.size() || value < 1 || value > 65535) {
        return std::nullopt;
    }
    return static_cast<std::uint16_t>(value);
}

}  // namespace

std::optional<IpAddress> parse_ip_address(std::string_view text) {
    if (auto v4 = parse_ipv4(text)) {
        return v4;
    }
    return parse_ipv6(text);
}

IpAddress ipv4_mapped(std::uint32_t v4) noexcept {
    IpAddress out{};
    out[10] = 0xFF;
    out[11] = 0xFF;
    out[12] = static_cast<std::uint8_t>((v4 >> 24U) & 0xFFU);
    out[13] = static_cast<std::uint8_t>((v4 >> 16U) & 0xFFU);
    out[14] = static_cast<std::uint8_t>((v4 >> 8U) & 0xFFU);
    out[15] = static_cast<std::uint8_t>(v4 & 0xFFU);
    return out;
}

bool is_ipv4_mapped(const IpAddress& address) noexcept {
    for (std::size_t i = 0; i < 10; ++i) {
        if (address[i] != 0) {
            return false;
        }
    }
    return address[10] == 0xFF && address[11] == 0xFF;
}

std::string ListenAddress::to_string() const {
    return is_ipv6() ? "[" + host + "]:" + std::to_string(port) : host + ":" + std::to_string(port);
}

namespace {

using HostAndPort = std::pair<std::string, std::uint16_t>;

/// "host:port" or "[IPv6]:port" (@p text; @p shown in the messages): an IPv6 literal
/// in brackets, or a host @p host_ok accepts (@p host_kind says what it must be),
/// and a port 1..65535. Every error ends with @p expected.
Parsed<HostAndPort> parse_host_port(std::string_view text, std::string_view shown, bool (*host_ok)(std::string_view),
                                    const char* host_kind, const std::string& expected) {
    using Result = Parsed<HostAndPort>;
    std::string_view host;
    std::string_view port;
    if (!text.empty() && text.front() == '[') {
        const auto close = text.find(']');
        if (close == std::string_view::npos || close + 1 >= text.size() || text[close + 1] != ':') {
            return Result::fail("'" + std::string(shown) + "' has no port after the IPv6 address; " + expected);
        }
        host = text.substr(1, close - 1);
        port = text.substr(close + 2);
        if (!parse_ipv6(host)) return Result::fail("'" + std::string(host) + "' is not an IPv6 address; " + expected);
    } else {
        const auto colon = text.rfind(':');
        if (colon == std::string_view::npos) {
            return Result::fail("'" + std::string(shown) + "' has no port; " + expected);
        }
        host = text.substr(0, colon);
        port = text.substr(colon + 1);
        if (host.find(':') != std::string_view::npos) {
            return Result::fail("'" + std::string(shown) + "': an IPv6 address needs brackets; " + expected);
        }
        if (!host_ok(host)) return Result::fail("'" + std::string(host) + "' is not " + host_kind + "; " + expected);
    }
    const auto port_number = parse_port(port);
    if (!port_number) return Result::fail("'" + std::string(port) + "' is not a port; expected 1..65535");
    return Result::ok(HostAndPort{std::string(host), *port_number});
}

bool is_ipv4(std::string_view host) { return parse_ipv4(host).has_value(); }

}  // namespace

Parsed<ListenAddress> parse_listen_address(std::string_view text) {
    const auto parsed =
        parse_host_port(text, text, &is_ipv4, "an IPv4 address (host names are not accepted for binding)",
                        "expected an IP address and a port, e.g. 0.0.0.0:502, 127.0.0.1:1502 or [::1]:1502");
    if (!parsed) return Parsed<ListenAddress>::fail(parsed.error);
    return Parsed<ListenAddress>::ok(ListenAddress{parsed.value->first, parsed.value->second});
}

std::string TcpEndpoint::to_string() const {
    const bool v6 = host.find(':') != std::string::npos;
    return (v6 ? "[" + host + "]" : host) + ":" + std::to_string(port);
}

bool is_tcp_port(std::string_view port) noexcept { return port.starts_with(tcp_port_scheme); }

Parsed<TcpEndpoint> parse_tcp_port(std::string_view text) {
    const std::string expected =
        "expected tcp://HOST:PORT, e.g. tcp://192.168.1.20:4001, tcp://[fd00::7]:4001 or tcp://nport-3:4001";
    if (!is_tcp_port(text)) {
        return Parsed<TcpEndpoint>::fail("'" + std::string(text) + "' does not start with tcp://; " + expected);
    }
    const auto parsed = parse_host_port(text.substr(tcp_port_scheme.size()), text, &is_valid_host,
                                        "a host name or an IPv4 address", expected);
    if (!parsed) return Parsed<TcpEndpoint>::fail(parsed.error);
    return Parsed<TcpEndpoint>::ok(TcpEndpoint{parsed.value->first, parsed.value->second});
}

bool is_valid_host(std::string_view host) {
    if (parse_ip_address(host)) {
        return true;
    }
    // RFC 1123 section 2.1: labels of letters, digits and hyphens, not starting or
    // ending with a hyphen, 1..63 characters; 253 characters in all.
    if (host.empty() || host.size() > 253) {
        return false;
    }
    std::size_t start = 0;
    while (start <= host.size()) {
        const std::size_t dot = std::min(host.find('.', start), host.size());
        const std::string_view label = host.substr(start, dot - start);
        if (label.empty() || label.size() > 63 || label.front() == '-' || label.back() == '-') {
            return false;
        }
        const bool chars_ok = std::all_of(label.begin(), label.end(), [](char c) {
            return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-';
        });
        if (!chars_ok) {
            return false;
        }
        start = dot + 1;
    }
    return true;
}

bool Cidr::contains(const IpAddress& address) const noexcept { return masked(address, prefix_length) == network; }

Parsed<Cidr> parse_cidr(std::string_view text) {
    using Result = Parsed<Cidr>;
    const std::string expected = "expected a network such as 10.0.0.0/8, 192.168.1.20 or fd00::/8";
    const auto slash = text.find('/');
    const std::string_view address_text = text.substr(0, slash);
    const bool v4 = parse_ipv4(address_text).has_value();
    const auto address = parse_ip_address(address_text);
    if (!address) {
        return Result::fail("'" + std::string(text) + "' is not a network: '" + std::string(address_text) +
                            "' is not an IP address; " + expected);
    }
    const unsigned max_prefix = v4 ? 32U : 128U;
    unsigned prefix = max_prefix;
    if (slash != std::string_view::npos) {
        const std::string_view prefix_text = text.substr(slash + 1);
        const auto [end, ec] = std::from_chars(prefix_text.data(), prefix_text.data() + prefix_text.size(), prefix);
        if (prefix_text.empty() || ec != std::errc{} || end != prefix_text.data() + prefix_text.size() ||
            prefix > max_prefix) {
            return Result::fail("'" + std::string(text) + "' has an invalid prefix length; expected /0../" +
                                std::to_string(max_prefix));
        }
    }
    const unsigned stored_prefix = v4 ? ipv4_mapped_prefix + prefix : prefix;
    const IpAddress network = masked(*address, stored_prefix);
    if (network != *address) {
        return Result::fail("'" + std::string(text) + "' has host bits set below the prefix; did you mean " +
                            format_ip(network) + "/" + std::to_string(prefix) + "?");
    }
    return Result::ok(Cidr{network, stored_prefix, std::string(text)});
}

}  // namespace fieldbridge::config
