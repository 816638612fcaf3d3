// Socket activation: which modbus_tcp.listen entry each socket passed by systemd
// serves, and the start-up errors when the socket unit and the configuration differ.
#include <doctest/doctest.h>

#include "daemon/passed_sockets.hpp"

namespace fieldbridge::daemon {
namespace {

[[nodiscard]] PassedSocket socket_on(int fd, const char* address, std::uint16_t port, const char* name = "unknown") {
    return PassedSocket{fd, name, asio::ip::tcp::endpoint(asio::ip::make_address(address), port)};
}

[[nodiscard]] config::ListenAddress entry(const char* host, std::uint16_t port) {
    return config::ListenAddress{host, port};
}

// For the error cases: the result is not wanted (doctest 2.4.11's CHECK_THROWS evaluates
// the expression as a statement, and GCC 14 warns about a [[nodiscard]] result left).
void match_for_error(const std::vector<config::ListenAddress>& entries, const std::vector<PassedSocket>& sockets) {
    static_cast<void>(match_passed_sockets(entries, sockets));
}

TEST_CASE("without passed sockets nothing is inherited: the server binds by itself") {
    CHECK(match_passed_sockets({entry("0.0.0.0", 502)}, {}).empty());
}

TEST_CASE("sockets match entries by address, in the order of modbus_tcp.listen") {
    const auto inherited = match_passed_sockets({entry("0.0.0.0", 502), entry("::1", 1502)},
                                                {socket_on(3, "::1", 1502), socket_on(4, "0.0.0.0", 502, "fieldbridge")});
    REQUIRE(inherited.size() == 2);
    CHECK(inherited[0].address == entry("0.0.0.0", 502));
    CHECK(inherited[0].fd == 4);
    CHECK(inherited[1].address == entry("::1", 1502));
    CHECK(inherited[1].fd == 3);
}

TEST_CASE("a socket named by a port serves the entry with that port, whatever it is bound to") {
    // ListenStream=502 binds [::]:502; the configuration says 0.0.0.0:502.
    const auto inherited = match_passed_sockets({entry("0.0.0.0", 502)}, {socket_on(3, "::", 502, "502")});
    REQUIRE(inherited.size() == 1);
    CHECK(inherited[0].fd == 3);
}

TEST_CASE("the address wins over the name") {
    const auto inherited = match_passed_sockets({entry("127.0.0.1", 1502), entry("127.0.0.1", 1503)},
                                                {socket_on(3, "127.0.0.1", 1502, "1503"), socket_on(4, "127.0.0.1", 1503)});
    REQUIRE(inherited.size() == 2);
    CHECK(inherited[0].fd == 3);
    CHECK(inherited[1].fd == 4);
}

TEST_CASE("a socket that matches no entry is an error naming it and the entries") {
    CHECK_THROWS_WITH_AS(match_for_error({entry("0.0.0.0", 502)}, {socket_on(3, "127.0.0.1", 1502)}),
                         doctest::Contains("fd 3 (FileDescriptorName=unknown, listening on 127.0.0.1:1502) matches no "
                                           "modbus_tcp.listen entry [0.0.0.0:502]"),
                         SocketActivationError);
    CHECK_THROWS_WITH_AS(match_for_error({entry("0.0.0.0", 502)}, {socket_on(3, "127.0.0.1", 1502, "1502")}),
                         doctest::Contains("matches no modbus_tcp.listen entry"), SocketActivationError);
}

TEST_CASE("an entry without a socket, while others were passed, is an error that says what to add") {
    CHECK_THROWS_WITH_AS(
        match_for_error({entry("0.0.0.0", 502), entry("::", 502)}, {socket_on(3, "0.0.0.0", 502)}),
        doctest::Contains("modbus_tcp.listen entry [::]:502 has no socket, while the service manager passed one; "
                          "add ListenStream=[::]:502"),
        SocketActivationError);
}

TEST_CASE("two sockets for one entry, an ambiguous port name, and a socket that is not listening are errors") {
    CHECK_THROWS_WITH_AS(
        match_for_error({entry("0.0.0.0", 502)}, {socket_on(3, "0.0.0.0", 502), socket_on(4, "::", 502, "502")}),
        doctest::Contains("two sockets were passed for modbus_tcp.listen entry 0.0.0.0:502"), SocketActivationError);
    CHECK_THROWS_WITH_AS(
        match_for_error({entry("127.0.0.1", 502), entry("::1", 502)}, {socket_on(3, "::", 502, "502")}),
        doctest::Contains("more than one modbus_tcp.listen entry"), SocketActivationError);
    CHECK_THROWS_WITH_AS(match_for_error({entry("0.0.0.0", 502)}, {PassedSocket{3, "fieldbridge", std::nullopt}}),
                         doctest::Contains("fd 3 (FileDescriptorName=fieldbridge) is not a listening TCP/IP socket"),
                         SocketActivationError);
}

}  // namespace
}  // namespace fieldbridge::daemon
