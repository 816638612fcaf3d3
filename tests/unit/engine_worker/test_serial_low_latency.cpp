// The low-latency request of a serial port (issue 14 item 7): played against drivers
// that take the flag, have it already, refuse it, drop it, or do not know the call.
// Through the real port on a pseudo-terminal: tests/integration/engine_worker.
#include <doctest/doctest.h>
#include <linux/serial.h>

#include <cerrno>
#include <vector>

#include "engine/serial_low_latency.hpp"
#include "fake_serial_driver.hpp"

namespace {

using namespace worker_test;
using Outcome = fe::LowLatency::Outcome;

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
