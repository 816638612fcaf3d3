#include "engine/tcp_stream_port.hpp"

#include <arpa/inet.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <utility>

#include "core/error.hpp"

namespace fieldbridge::engine {
namespace {

// Keepalive on an idle connection: first probe after 5 s, then every 2 s, 3 lost
// probes end it (11 s). TCP_USER_TIMEOUT bounds unacknowledged data the same way:
// while the line polls, a device server that lost power is noticed within 10 s even
// though keepalive never runs on a busy connection.
constexpr int keepalive_idle_s = 5;
constexpr int keepalive_interval_s = 2;
constexpr int keepalive_count = 3;
constexpr unsigned user_timeout_ms = 10000;

[[nodiscard]] std::string address_text(const sockaddr* address) {
    char host[INET6_ADDRSTRLEN] = {};
    std::uint16_t port = 0;
    if (address->sa_family == AF_INET6) {
        const auto* v6 = reinterpret_cast<const sockaddr_in6*>(address);
        ::inet_ntop(AF_INET6, &v6->sin6_addr, host, sizeof host);
        port = ntohs(v6->sin6_port);
        return "[" + std::string(host) + "]:" + std::to_string(port);
    }
    const auto* v4 = reinterpret_cast<const sockaddr_in*>(address);
    ::inet_ntop(AF_INET, &v4->sin_addr, host, sizeof host);
    port = ntohs(v4->sin_port);
    return std::string(host) + ":" + std::to_string(port);
}

constexpr const char* check_server =
    "check that the device server is powered and reachable, that its port is in TCP server (transparent) "
    "mode on this port number, and that no other client holds its only connection";

}  // namespace

TcpStreamPort::TcpStreamPort(SerialSettings settings, ConnectWait wait) : settings_(std::move(settings)), wait_(wait) {
    if (!settings_.tcp) throw core::InvalidArgument("tcp stream port " + settings_.path + ": no tcp endpoint given");
}

TcpStreamPort::~TcpStreamPort() { close(); }

void TcpStreamPort::fail(const std::string& what, int error, const char* advice) {
    close();
    std::string text = settings_.path + ": " + what;
    if (error != 0) text += " (" + std::string(std::strerror(error)) + ")";
    throw SerialPortError(text + "; " + advice);
}

std::string TcpStreamPort::peer() const { return connected_to_.empty() ? settings_.path : connected_to_; }

void TcpStreamPort::resolve() {
    addrinfo hints{};
    hints.ai_family = AF_UNSPEC;
    hints.ai_socktype = SOCK_STREAM;
    // No AI_ADDRCONFIG: it drops IPv4 on a box whose only IPv4 address is loopback.
    hints.ai_flags = AI_NUMERICSERV;
    addrinfo* found = nullptr;
    const std::string service = std::to_string(settings_.tcp->port);
    const int rc = ::getaddrinfo(settings_.tcp->host.c_str(), service.c_str(), &hints, &found);
    if (rc != 0) {
        const std::string why = rc == EAI_SYSTEM ? std::strerror(errno) : ::gai_strerror(rc);
        close();
        throw SerialPortError(settings_.path + ": cannot resolve host '" + settings_.tcp->host + "' (" + why +
                              "); check the name in the line's port, /etc/hosts and the DNS settings, or give "
                              "the device server's IP address");
    }
    std::vector<std::vector<std::uint8_t>> addresses;
    for (const addrinfo* a = found; a != nullptr; a = a->ai_next) {
        const auto* bytes = reinterpret_cast<const std::uint8_t*>(a->ai_addr);
        addresses.emplace_back(bytes, bytes + a->ai_addrlen);
    }
    ::freeaddrinfo(found);
    if (addresses != addresses_) {
        addresses_ = std::move(addresses);
        next_address_ = 0;
    }
}

void TcpStreamPort::set_options() {
    const int on = 1;
    // Modbus requests are small and each waits for its answer: Nagle would hold one
    // back until the previous segment is acknowledged.
    if (::setsockopt(fd_, IPPROTO_TCP, TCP_NODELAY, &on, sizeof on) == -1) {
        fail("cannot set TCP_NODELAY", errno, "report it");
    }
    const int idle = keepalive_idle_s;
    const int interval = keepalive_interval_s;
    const int count = keepalive_count;
    const unsigned user_timeout = user_timeout_ms;
    if (::setsockopt(fd_, SOL_SOCKET, SO_KEEPALIVE, &on, sizeof on) == -1 ||
        ::setsockopt(fd_, IPPROTO_TCP, TCP_KEEPIDLE, &idle, sizeof idle) == -1 ||
        ::setsockopt(fd_, IPPROTO_TCP, TCP_KEEPINTVL, &interval, sizeof interval) == -1 ||
        ::setsockopt(fd_, IPPROTO_TCP, TCP_KEEPCNT, &count, sizeof count) == -1 ||
        ::setsockopt(fd_, IPPROTO_TCP, TCP_USER_TIMEOUT, &user_timeout, sizeof user_timeout) == -1) {
        fail("cannot set TCP keepalive", errno, "report it");
    }
}

void TcpStreamPort::open() {
    if (is_open()) return;
    resolve();
    const auto& address = addresses_[next_address_ % addresses_.size()];
    // The next attempt (after a failure) tries the next address the name gave.
    next_address_ = (next_address_ + 1) % addresses_.size();
    const auto* sa = reinterpret_cast<const sockaddr*>(address.data());
    connected_to_ = address_text(sa);
    fd_ = ::socket(sa->sa_family, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    if (fd_ < 0) fail("cannot create a socket", errno, "check the system's file descriptor limit");
    set_options();
    if (::connect(fd_, sa, static_cast<socklen_t>(address.size())) == 0) return;
    if (errno != EINPROGRESS) {
        fail("cannot connect to " + connected_to_, errno, check_server);
    }
    opening_ = true;
    if (wait_ == ConnectWait::begin) return;
    pollfd watch{fd_, POLLOUT, 0};
    const int ready = ::poll(&watch, 1, static_cast<int>(settings_.tcp->connect_timeout.count()));
    if (ready == 0) {
        fail("no answer from " + connected_to_ + " within " + std::to_string(settings_.tcp->connect_timeout.count()) +
                 " ms (connect_timeout)",
             0, check_server);
    }
    if (ready < 0) fail("cannot wait for the connection", errno, "report it");
    finish_open();
}

void TcpStreamPort::finish_open() {
    if (!opening_) return;
    opening_ = false;
    int error = 0;
    socklen_t length = sizeof error;
    if (::getsockopt(fd_, SOL_SOCKET, SO_ERROR, &error, &length) == -1) error = errno;
    if (error != 0) fail("cannot connect to " + connected_to_, error, check_server);
}

std::string TcpStreamPort::open_detail() const {
    return "connected to " + connected_to_ + " (TCP_NODELAY, keepalive " + std::to_string(keepalive_idle_s) + " s)";
}

void TcpStreamPort::close() noexcept {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
    opening_ = false;
}

std::size_t TcpStreamPort::write_some(protocol::ByteView bytes) {
    if (bytes.empty()) return 0;
    const ssize_t n = ::send(fd_, bytes.data(), bytes.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
    if (n >= 0) return static_cast<std::size_t>(n);
    if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) return 0;
    fail("sending to " + peer() + " failed", errno, "the connection to the device server broke; it is reopened");
}

std::size_t TcpStreamPort::read_some(std::span<std::uint8_t> buffer) {
    const ssize_t n = ::recv(fd_, buffer.data(), buffer.size(), MSG_DONTWAIT);
    if (n > 0) return static_cast<std::size_t>(n);
    if (n == 0) {
        fail("the device server " + peer() + " closed the connection", 0,
             "it may have restarted, or given its only connection to another client; it is reopened");
    }
    if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) return 0;
    fail("receiving from " + peer() + " failed", errno, "the connection to the device server broke; it is reopened");
}

void TcpStreamPort::discard_input() noexcept {
    if (fd_ < 0) return;
    std::uint8_t sink[256];
    while (::recv(fd_, sink, sizeof sink, MSG_DONTWAIT) > 0) {
    }
}

}  // namespace fieldbridge::engine
