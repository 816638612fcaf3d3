// The low-latency request through the real port (issue 14 item 7): asked at each
// open through the port's seam, and a pseudo-terminal, which does not know the call.
#include <doctest/doctest.h>

#include "engine/posix_serial_port.hpp"
#include "engine/serial_low_latency.hpp"
#include "fake_serial_driver.hpp"
#include "pty_device.hpp"

namespace {

using namespace worker_test;
using LowLatencyOutcome = fe::LowLatency::Outcome;

}  // namespace

TEST_CASE("low latency: the port asks at each open through its seam; a pseudo-terminal does not know the call") {
    TempDir dir;
    asio::io_context io;
    const auto link = dir.path() / "ttyLL";
    PtyDevice device(io, link);
    fe::SerialSettings settings;
    settings.path = link.string();

    FakeDriver driver;
    fe::PosixSerialPort faked(settings, driver.ioctls());
    CHECK(faked.low_latency().outcome == LowLatencyOutcome::not_requested);
    faked.open();
    CHECK(faked.low_latency().outcome == LowLatencyOutcome::enabled);
    faked.close();
    faked.open();
    CHECK(faked.low_latency().outcome == LowLatencyOutcome::already_on);
    CHECK(driver.set_flags.size() == 1);

    fe::PosixSerialPort real(settings);
    real.open();
    CHECK(real.low_latency().outcome == LowLatencyOutcome::not_supported);
}
