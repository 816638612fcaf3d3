// Wire-time arithmetic (product spec section 9) and the latency histogram.
#include <doctest/doctest.h>

#include <stdexcept>

#include "core/error.hpp"
#include "engine/line_stats.hpp"
#include "engine/line_timing.hpp"
#include "engine/transaction.hpp"
#include "line_test_support.hpp"

namespace {

using namespace line_test;
using std::chrono::nanoseconds;

TEST_CASE("timing: 115200 8N1 character, t1.5 and t3.5 (rounded up)") {
    const fe::LineTiming timing({115200, 8, false, 1});
    CHECK(timing.bits_per_character() == 10);
    CHECK(timing.character_time() == nanoseconds{86'806});  // 86805.55
    CHECK(timing.t1_5() == nanoseconds{130'209});           // 130208.33
    CHECK(timing.t3_5() == nanoseconds{303'820});           // 303819.44, spec: 0.304 ms
    CHECK(timing.wire_time(0) == nanoseconds{0});
    CHECK(timing.wire_time(8) == nanoseconds{694'445});     // 694444.4
}

TEST_CASE("timing: the product spec's 2-register read at 115200 with 1 ms turnaround") {
    const fe::LineTiming timing({115200, 8, false, 1});
    // Spec section 9: (8 + 9) tc + 2 t3.5 + 1 ms = 1.476 + 0.608 + 1 = 3.083 ms.
    CHECK(timing.wire_time(17) == nanoseconds{1'475'695});
    const auto line = timing.transaction_time(8, 9, 1ms);
    CHECK(line == nanoseconds{1'475'695 + 2 * 303'820 + 1'000'000});
    CHECK(line > 3'083us);
    CHECK(line < 3'084us);
    CHECK(std::chrono::seconds{1} / line == 324);  // "324 transactions/s at most"
    // "The earliest answer a client can see is 2.78 ms": request, t3.5, turnaround, reply.
    const auto earliest = timing.wire_time(17) + timing.t3_5() + 1ms;
    CHECK(earliest > 2'779us);
    CHECK(earliest < 2'780us);
}

TEST_CASE("timing: parity or two stop bits make 11-bit characters") {
    const fe::LineTiming even({9600, 8, true, 1});
    CHECK(even.bits_per_character() == 11);
    CHECK(even.character_time() == nanoseconds{1'145'834});  // 1145833.3
    CHECK(even.t3_5() == nanoseconds{4'010'417});            // 4010416.6
    const fe::LineTiming two_stop({9600, 8, false, 2});
    CHECK(two_stop.bits_per_character() == 11);
    CHECK(two_stop.character_time() == even.character_time());
    const fe::LineTiming seven_bits({9600, 7, true, 1});
    CHECK(seven_bits.bits_per_character() == 10);
}

TEST_CASE("timing: the Modbus fixed timers apply above 19200 bit/s only, and only when chosen") {
    const fe::LineTiming fixed({115200, 8, false, 1}, fe::InterFrameRule::modbus_fixed_above_19200);
    CHECK(fixed.t3_5() == 1750us);
    CHECK(fixed.t1_5() == 750us);
    CHECK(fixed.character_time() == nanoseconds{86'806});  // tc itself never changes
    const fe::LineTiming at_19200({19200, 8, false, 1}, fe::InterFrameRule::modbus_fixed_above_19200);
    CHECK(at_19200.t3_5() == nanoseconds{1'822'917});  // 3.5 x 10 / 19200
    const fe::LineTiming per_char({115200, 8, false, 1});
    CHECK(per_char.rule() == fe::InterFrameRule::per_character);
    CHECK(per_char.t3_5() < fixed.t3_5());
}

TEST_CASE("timing: impossible formats are refused with the reason") {
    CHECK_THROWS_WITH_AS(fe::LineTiming({0, 8, false, 1}), doctest::Contains("baud"),
                         fieldbridge::core::InvalidArgument);
    CHECK_THROWS_WITH_AS(fe::LineTiming({9600, 8, false, 3}), doctest::Contains("stop bits"),
                         fieldbridge::core::InvalidArgument);
    CHECK_THROWS_WITH_AS(fe::LineTiming({9600, 9, false, 1}), doctest::Contains("data bits"),
                         fieldbridge::core::InvalidArgument);
}

TEST_CASE("timing: the line config maps to the character format") {
    fe::LineTimingConfig config;
    config.baud = 57600;
    config.parity = true;
    config.stop_bits = 1;
    const auto format = config.format();
    CHECK(format.baud == 57600);
    CHECK(format.parity);
    CHECK(format.data_bits == 8);
    CHECK(fe::LineTiming(format).bits_per_character() == 11);
}

TEST_CASE("latency histogram: buckets, sum, max and quantile bounds") {
    fe::LatencyHistogram histogram;
    CHECK(histogram.count() == 0);
    CHECK(histogram.quantile_upper_bound(0.5) == Duration{});
    histogram.record(400us);   // bucket 0 (<= 500 us)
    histogram.record(1ms);     // bucket 1 (<= 1 ms, inclusive)
    histogram.record(2500us);  // bucket 3 (<= 3 ms)
    histogram.record(3ms);     // bucket 3
    histogram.record(2s);      // overflow
    CHECK(histogram.count() == 5);
    CHECK(histogram.bucket(0) == 1);
    CHECK(histogram.bucket(1) == 1);
    CHECK(histogram.bucket(2) == 0);
    CHECK(histogram.bucket(3) == 2);
    CHECK(histogram.bucket(fe::LatencyHistogram::bucket_count - 1) == 1);
    CHECK(histogram.sum() == 400us + 1ms + 2500us + 3ms + 2s);
    CHECK(histogram.max() == 2s);
    CHECK(histogram.quantile_upper_bound(0.2) == 500us);
    CHECK(histogram.quantile_upper_bound(0.5) == 3ms);
    CHECK(histogram.quantile_upper_bound(0.8) == 3ms);
    CHECK(histogram.quantile_upper_bound(1.0) == 2s);
}

TEST_CASE("outcome and log level names") {
    CHECK(std::string(fe::to_string(fe::OutcomeStatus::ok)) == "ok");
    CHECK(std::string(fe::to_string(fe::OutcomeStatus::device_offline)) == "device_offline");
    CHECK(std::string(fe::to_string(fe::OutcomeStatus::broadcast_sent)) == "broadcast_sent");
    CHECK(std::string(fe::to_string(fe::OutcomeStatus::invalid_request)) == "invalid_request");
    CHECK(std::string(fe::to_string(fe::LogLevel::warning)) == "warning");
    CHECK(std::string(fe::to_string(fe::MasterState::awaiting_reply)) == "awaiting_reply");
}

}  // namespace
