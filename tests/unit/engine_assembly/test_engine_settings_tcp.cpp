// From the configuration to the engine for a line on a tcp:// port and paced devices
// (issue 27): the port the factory builds, the stream framing, the reconnect back-off
// and the per-device pacing reach the line's parts.
#include <doctest/doctest.h>

#include <chrono>

#include "config/config_loader.hpp"
#include "engine/engine.hpp"
#include "engine/engine_settings.hpp"
#include "engine/posix_serial_port.hpp"
#include "engine/tcp_stream_port.hpp"

namespace {

namespace fc = fieldbridge::config;
namespace fe = fieldbridge::engine;
using namespace std::chrono_literals;

constexpr const char* yaml = R"(
gateway: {id: t}
lines:
  - name: tcp-line
    port: "tcp://[fd00::7]:4001"
    baud: 19200
    tcp_frame_gap: 12ms
    request_gap: 4ms
    connect_timeout: 700ms
    reconnect_backoff: {initial: 100ms, max: 800ms}
    devices:
      - {name: meter, type: hiwin-xeg, address: 1, unit_id: 1, request_gap: 30ms, first_request_delay: 2s}
  - name: tty-line
    port: /dev/ttyS3
    offline_backoff: {initial: 2s, max: 20s}
    devices:
      - {name: other, type: hiwin-xeg, address: 1, unit_id: 2}
)";

TEST_CASE("engine settings: a tcp:// line is a stream with its own framing gap, connect and back-off") {
    const auto config = fc::load_config_string(yaml, "t.yaml");
    const auto& tcp = config->lines.at(0);
    const fe::SerialSettings settings = fe::serial_settings(tcp);
    REQUIRE(settings.tcp.has_value());
    CHECK(settings.tcp->host == "fd00::7");
    CHECK(settings.tcp->port == 4001);
    CHECK(settings.tcp->connect_timeout == 700ms);
    CHECK(settings.path == "tcp://[fd00::7]:4001");
    CHECK(dynamic_cast<fe::TcpStreamPort*>(fe::posix_port_factory()(settings).get()) != nullptr);

    const fe::LineTimingConfig timing = fe::line_timing(tcp);
    CHECK(timing.stream);
    CHECK(timing.frame_gap == 12ms);
    CHECK(timing.request_gap == 4ms);
    CHECK(timing.baud == 19200);
    const fe::LineWorkerConfig worker = fe::line_worker_config(tcp);
    CHECK(worker.reopen_initial == 100ms);
    CHECK(worker.reopen_max == 800ms);
    const fe::DeviceLimits limits = fe::device_limits(tcp, tcp.devices.at(0));
    CHECK(limits.request_gap == 30ms);
    CHECK(limits.first_request_delay == 2s);
}

TEST_CASE("engine settings: a tty line stays a serial port that reopens on offline_backoff, without pacing") {
    const auto config = fc::load_config_string(yaml, "t.yaml");
    const auto& tty = config->lines.at(1);
    const fe::SerialSettings settings = fe::serial_settings(tty);
    CHECK_FALSE(settings.tcp.has_value());
    CHECK(dynamic_cast<fe::PosixSerialPort*>(fe::posix_port_factory()(settings).get()) != nullptr);
    CHECK_FALSE(fe::line_timing(tty).stream);
    CHECK(fe::line_worker_config(tty).reopen_initial == 2s);
    CHECK(fe::device_limits(tty, tty.devices.at(0)).request_gap == 0ms);
}

}  // namespace
