// The low-latency request of a serial port (issue 14 item 7): played against drivers
// that take the flag, have it already, refuse it, drop it, or do not know the call,
// and through the real port on a pseudo-terminal (which does not know it).
#include <doctest/doctest.h>
#include <linux/serial.h>

#include <cerrno>
#include <vector>

#include "engine/posix_serial_port.hpp"
#include "engine/serial_low_latency.hpp"
#include "worker_test_support.hpp"

namespace {

using namespace worker_test;
using Outcome = fe::LowLatency::Outcome;

/// A driver's serial_struct and what the test wants its ioctls to do.
struct FakeDriver {
    int flags = 0;
    int get_error = 0;
    int set_error = 0;
    bool drops_flag = false;
    std::vector<int> set_flags;  ///< the flags of each TIOCSSERIAL

    fe::SerialIoctls ioctls() {
        return fe::SerialIoctls{
            [this](int, serial_struct& out) {
                if (get_error != 0) return get_error;
                out.flags = flags;
                return 0;
            },
            [this](int, const serial_struct& in) {
                set_flags.push_back(in.flags);
                if (set_error != 0) return set_error;
                flags = drops_flag ? (in.flags & ~ASYNC_LOW_LATENCY) : in.flags;
                return 0;
            },
        };
    }
};

}  // namespace

TEST_CASE("low latency: the flag is added to what the driver has, and read back") {
    FakeDriver driver;
    driver.flags = ASYNC_SKIP_TEST;
    const fe::LowLatency result = fe::request_low_latency(3, driver.ioctls());
    CHECK(result.outcome == Outcome::enabled);
    CHECK(driver.set_flags == std::vector<int>{ASYNC_SKIP_TEST | ASYNC_LOW_LATENCY});
    CHECK(fe::to_string(result) == "low latency on");
}

TEST_CASE("low latency: already on, nothing is written") {
    FakeDriver driver;
    driver.flags = ASYNC_LOW_LATENCY;
    CHECK(fe::request_low_latency(3, driver.ioctls()).outcome == Outcome::already_on);
    CHECK(driver.set_flags.empty());
}

TEST_CASE("low latency: a driver without the call, one that refuses it, one that drops the flag") {
    FakeDriver none;
    none.get_error = ENOTTY;
    const fe::LowLatency unsupported = fe::request_low_latency(3, none.ioctls());
    CHECK(unsupported.outcome == Outcome::not_supported);
    CHECK(unsupported.error == ENOTTY);
    CHECK(fe::to_string(unsupported).find("not supported by the driver") != std::string::npos);

    FakeDriver refusing;
    refusing.set_error = EPERM;
    const fe::LowLatency refused = fe::request_low_latency(3, refusing.ioctls());
    CHECK(refused.outcome == Outcome::refused);
    CHECK(refused.error == EPERM);
    CHECK(fe::to_string(refused).find("latency timer") != std::string::npos);

    FakeDriver dropping;
    dropping.drops_flag = true;
    CHECK(fe::request_low_latency(3, dropping.ioctls()).outcome == Outcome::refused);
}

TEST_CASE("low latency: the port asks at each open through its seam; a pseudo-terminal does not know the call") {
    TempDir dir;
    asio::io_context io;
    const auto link = dir.path() / "ttyLL";
    PtyDevice device(io, link);
    fe::SerialSettings settings;
    settings.path = link.string();

    FakeDriver driver;
    fe::PosixSerialPort faked(settings, driver.ioctls());
    CHECK(faked.low_latency().outcome == Outcome::not_requested);
    faked.open();
    CHECK(faked.low_latency().outcome == Outcome::enabled);
    faked.close();
    faked.open();
    CHECK(faked.low_latency().outcome == Outcome::already_on);
    CHECK(driver.set_flags.size() == 1);

    fe::PosixSerialPort real(settings);
    real.open();
    CHECK(real.low_latency().outcome == Outcome::not_supported);
}
