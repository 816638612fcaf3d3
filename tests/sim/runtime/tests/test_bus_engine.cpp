#include <doctest/doctest.h>


#include "bus_engine.hpp"
#include "fake_device.hpp"
#include "null_log.hpp"

namespace fieldbridge::sim::runtime {
namespace {

using namespace std::chrono_literals;
using protocol::Bytes;
using test::ascii;
using test::FakeDevice;

// XEG Appendix 1: read gripper model, id 2, and its reply (001, Appendix 1, steps 3-4).
const Bytes read_model{0x02, 0x03, 0x06, 0x00, 0x00, 0x01, 0x84, 0xB1};
const Bytes model_reply{0x02, 0x03, 0x02, 0x0A, 0x20, 0xFB, 0x3C};
// XEG Appendix 1: read status, id 2.
const Bytes read_status{0x02, 0x04, 0x03, 0x01, 0x00, 0x01, 0x60, 0x7D};
// XEG Appendix 1, step 21: broadcast Move (nobody answers).
const Bytes broadcast_move{0x00, 0x10, 0x06, 0x30, 0x00, 0x03, 0x06, 0x0C,
                           0x80, 0x1F, 0x40, 0x00, 0x01, 0x3C, 0xA4};

using test::null_log;

struct Bench {
    explicit Bench(bool wire_time, std::vector<std::unique_ptr<BusDevice>> devices = {}) {
        if (devices.empty()) {
            auto device = std::make_unique<FakeDevice>(BusProtocol::modbus_rtu, 2, model_reply);
            xeg = device.get();
            devices.push_back(std::move(device));
        }
        BusSettings settings{"line-t", LineTiming{115200, 10}, wire_time, 1ms, 42};
        engine = std::make_unique<BusEngine>(std::move(settings), std::move(devices), null_log(), t0);
    }
    Clock::time_point t0 = Clock::time_point{} + 1h;
    FakeDevice* xeg = nullptr;
    std::unique_ptr<BusEngine> engine;
};

}  // namespace

TEST_CASE("line timing: character and silence times at 115200 8N1 and 9600 8E1") {
    constexpr LineTiming fast{115200, 10};
    CHECK(fast.bytes(8).count() == 694445);    // 80 bits / 115200
    CHECK(fast.bytes(17).count() == 1475695);  // spec section 9: 1.476 ms
    CHECK(fast.silence().count() == 303820);   // 3.5 characters
    constexpr LineTiming slow{9600, 11};
    CHECK(slow.character().count() == 1145834);
}

TEST_CASE("without wire time a reply is due at once") {
    Bench bench(false);
    bench.engine->on_bytes(read_model, bench.t0);
    REQUIRE(bench.xeg->frames.size() == 1);
    CHECK(bench.xeg->frames[0] == read_model);
    CHECK(bench.xeg->advances >= 1);  // advanced before the frame
    auto due = bench.engine->take_due(bench.t0);
    REQUIRE(due.size() == 1);
    CHECK(due[0].bytes == model_reply);
    CHECK(due[0].reply);
    CHECK(bench.engine->counters().requests == 1);
}

TEST_CASE("wire time: the reply is due after request, turnaround and reply on the wire") {
    Bench bench(true);
    const LineTiming timing{115200, 10};
    bench.engine->on_bytes(read_model, bench.t0);
    const auto expected = bench.t0 + timing.bytes(8) + timing.silence() + 1ms + timing.bytes(7);
    REQUIRE(bench.engine->next_output() == expected);
    CHECK(bench.engine->take_due(expected - 1ns).empty());
    auto due = bench.engine->take_due(expected);
    REQUIRE(due.size() == 1);
    bench.engine->on_written(due[0], due[0].bytes.size(), expected + 20us);
    const auto& counters = bench.engine->counters();
    CHECK(counters.replies == 1);
    CHECK(counters.timing.writes == 1);
    CHECK(counters.timing.late_max == 20us);
    CHECK(counters.busy == timing.bytes(8) + timing.bytes(7));
}

TEST_CASE("a request sent before 3.5 characters of silence is a gap violation") {
    Bench bench(true);
    const LineTiming timing{115200, 10};
    bench.engine->on_bytes(read_model, bench.t0);
    const auto reply_at = *bench.engine->next_output();
    (void)bench.engine->take_due(reply_at);
    bench.engine->on_bytes(read_status, reply_at + 100us);  // too early
    CHECK(bench.engine->counters().gap_violations == 1);
    const auto second = *bench.engine->next_output();
    (void)bench.engine->take_due(second);
    bench.engine->on_bytes(read_status, second + timing.silence());  // exactly on time
    CHECK(bench.engine->counters().gap_violations == 1);
    CHECK(bench.engine->counters().min_silence == 100us);
    CHECK(bench.engine->counters().requests == 3);
}

TEST_CASE("the silence window: requests and the longest idle time before one, since the previous call") {
    Bench bench(true);
    const LineTiming timing{115200, 10};
    bench.engine->on_bytes(read_model, bench.t0);
    auto reply_at = *bench.engine->next_output();
    (void)bench.engine->take_due(reply_at);
    bench.engine->on_bytes(read_status, reply_at + 5ms);  // the line sat idle 5 ms
    const auto first = bench.engine->take_silence_window();
    CHECK(first["requests"] == 2);
    CHECK(first["max_silence_us"].get<double>() == doctest::Approx(5000.0));
    reply_at = *bench.engine->next_output();
    (void)bench.engine->take_due(reply_at);
    bench.engine->on_bytes(read_status, reply_at + timing.silence());
    const auto second = bench.engine->take_silence_window();  // a new window: the 5 ms is gone
    CHECK(second["requests"] == 1);
    CHECK(second["max_silence_us"].get<double>() ==
          doctest::Approx(std::chrono::duration<double, std::micro>(timing.silence()).count()));
    CHECK(bench.engine->take_silence_window()["requests"] == 0);
}

TEST_CASE("two requests back to back: a gap violation after a broadcast, a collision after a reply") {
    Bench bench(true);
    Bytes both = broadcast_move;
    both.insert(both.end(), read_status.begin(), read_status.end());
    bench.engine->on_bytes(both, bench.t0);
    CHECK(bench.engine->counters().broadcasts == 1);
    CHECK(bench.engine->counters().gap_violations == 1);
    CHECK(bench.engine->counters().requests == 2);

    Bench replied(true);
    Bytes two = read_model;
    two.insert(two.end(), read_status.begin(), read_status.end());
    replied.engine->on_bytes(two, replied.t0);
    CHECK(replied.engine->counters().requests == 1);
    CHECK(replied.engine->counters().collisions == 1);
    CHECK(replied.engine->counters().collision_bytes == read_status.size());
    // The pending reply is still delivered.
    REQUIRE(replied.engine->next_output());
    CHECK(replied.engine->take_due(*replied.engine->next_output()).size() == 1);
}

TEST_CASE("bytes arriving while a reply is pending collide and are discarded") {
    Bench bench(true);
    bench.engine->on_bytes(read_model, bench.t0);
    bench.engine->on_bytes(read_status, bench.t0 + 1ms);
    CHECK(bench.engine->counters().collisions == 1);
    CHECK(bench.xeg->frames.size() == 1);
}

TEST_CASE("garbage ahead of a frame is skipped and counted") {
    Bench bench(false);
    Bytes noisy{0xAA, 0xBB};
    noisy.insert(noisy.end(), read_model.begin(), read_model.end());
    bench.engine->on_bytes(noisy, bench.t0);
    if (bench.engine->resync_deadline()) {
        bench.engine->on_silence(*bench.engine->resync_deadline());
    }
    CHECK(bench.engine->counters().requests == 1);
    CHECK(bench.engine->counters().garbage_bytes == 2);
    CHECK(bench.xeg->frames.size() == 1);
    CHECK(bench.engine->take_due(bench.t0 + 1s).size() == 1);
}

TEST_CASE("a request with a bad CRC is counted and not answered") {
    Bench bench(false);
    Bytes bad = read_model;
    bad.back() ^= 0x01;
    bench.engine->on_bytes(bad, bench.t0);
    if (bench.engine->resync_deadline()) {
        bench.engine->on_silence(*bench.engine->resync_deadline());
    }
    CHECK(bench.engine->counters().requests == 0);
    CHECK(bench.engine->counters().crc_errors + bench.engine->counters().garbage_bytes > 0);
    CHECK(bench.xeg->frames.empty());
    CHECK_FALSE(bench.engine->next_output());
}

TEST_CASE("a mixed bus hands '>' frames to ASCII devices and the rest to RTU devices") {
    std::vector<std::unique_ptr<BusDevice>> devices;
    auto rtu = std::make_unique<FakeDevice>(BusProtocol::modbus_rtu, 2, model_reply);
    auto wtec = std::make_unique<FakeDevice>(BusProtocol::wtec_ascii, 1, ascii(">01d0136DE\r\n"));
    auto* rtu_device = rtu.get();
    auto* ascii_device = wtec.get();
    devices.push_back(std::move(rtu));
    devices.push_back(std::move(wtec));
    Bench bench(false, std::move(devices));
    bench.engine->on_bytes(ascii(">01dB819\r\n"), bench.t0);
    auto due = bench.engine->take_due(bench.t0);
    REQUIRE(due.size() == 1);
    CHECK(due[0].bytes == ascii(">01d0136DE\r\n"));
    bench.engine->on_bytes(read_model, bench.t0 + 10ms);
    due = bench.engine->take_due(bench.t0 + 10ms);
    REQUIRE(due.size() == 1);
    CHECK(due[0].bytes == model_reply);
    REQUIRE(ascii_device->frames.size() == 1);
    CHECK(ascii_device->frames[0] == ascii(">01dB819\r\n"));
    REQUIRE(rtu_device->frames.size() == 1);
    CHECK(rtu_device->frames[0] == read_model);
    CHECK(bench.engine->counters().garbage_bytes == 0);
}

TEST_CASE("wire time: several replies to one broadcast follow each other") {
    std::vector<std::unique_ptr<BusDevice>> devices;
    devices.push_back(std::make_unique<FakeDevice>(BusProtocol::wtec_ascii, 1, ascii(">01$01E2DF\r\n"), true));
    devices.push_back(std::make_unique<FakeDevice>(BusProtocol::wtec_ascii, 2, ascii(">02$02A79F\r\n"), true));
    Bench bench(true, std::move(devices));
    const LineTiming timing{115200, 10};
    bench.engine->on_bytes(ascii(">00$D819\r\n"), bench.t0);
    const auto first = bench.t0 + timing.bytes(10) + timing.silence() + 1ms + timing.bytes(12);
    const auto second = first + timing.silence() + 1ms + timing.bytes(12);
    auto due = bench.engine->take_due(second);
    REQUIRE(due.size() == 2);
    CHECK(due[0].at == first);
    CHECK(due[1].at == second);
    CHECK(due[1].bytes == ascii(">02$02A79F\r\n"));
}

TEST_CASE("reply faults: drop, corrupt-crc, truncate, garbage, delay, echo") {
    const auto fault = [](std::string_view text) { return parse_fault_spec(text); };
    SUBCASE("drop next=1 drops one reply") {
        Bench bench(false);
        bench.engine->apply_fault(fault("line-t@2:drop:next=1"));
        bench.engine->on_bytes(read_model, bench.t0);
        CHECK(bench.engine->take_due(bench.t0).empty());
        bench.engine->on_bytes(read_model, bench.t0 + 10ms);
        CHECK(bench.engine->take_due(bench.t0 + 10ms).size() == 1);
        CHECK(bench.engine->counters().dropped == 1);
    }
    SUBCASE("corrupt-crc changes the CRC only") {
        Bench bench(false);
        bench.engine->apply_fault(fault("line-t:corrupt-crc"));
        bench.engine->on_bytes(read_model, bench.t0);
        const auto due = bench.engine->take_due(bench.t0);
        REQUIRE(due.size() == 1);
        CHECK(due[0].bytes.size() == model_reply.size());
        CHECK(std::equal(model_reply.begin(), model_reply.end() - 1, due[0].bytes.begin()));
        CHECK(due[0].bytes.back() != model_reply.back());
    }
    SUBCASE("truncate sends the first half") {
        Bench bench(false);
        bench.engine->apply_fault(fault("line-t@2:truncate"));
        bench.engine->on_bytes(read_model, bench.t0);
        const auto due = bench.engine->take_due(bench.t0);
        REQUIRE(due.size() == 1);
        CHECK(due[0].bytes == Bytes(model_reply.begin(), model_reply.begin() + 3));
    }
    SUBCASE("garbage goes ahead of the intact reply") {
        Bench bench(false);
        bench.engine->apply_fault(fault("line-t:garbage"));
        bench.engine->on_bytes(read_model, bench.t0);
        const auto due = bench.engine->take_due(bench.t0);
        REQUIRE(due.size() == 1);
        REQUIRE(due[0].bytes.size() > model_reply.size());
        CHECK(std::equal(model_reply.rbegin(), model_reply.rend(), due[0].bytes.rbegin()));
    }
    SUBCASE("delay adds latency") {
        Bench bench(false);
        bench.engine->apply_fault(fault("line-t:delay:25"));
        bench.engine->on_bytes(read_model, bench.t0);
        CHECK(bench.engine->next_output() == bench.t0 + 25ms);
    }
    SUBCASE("echo sends the request back before the reply") {
        Bench bench(true);
        bench.engine->apply_fault(fault("line-t:echo"));
        bench.engine->on_bytes(read_model, bench.t0);
        const auto due = bench.engine->take_due(bench.t0 + 1s);
        REQUIRE(due.size() == 2);
        CHECK(due[0].bytes == read_model);
        CHECK_FALSE(due[0].reply);
        CHECK(due[1].bytes == model_reply);
    }
}

TEST_CASE("a dead device ignores frames until revived") {
    Bench bench(false);
    bench.engine->apply_fault(parse_fault_spec("line-t@2:dead"));
    bench.engine->on_bytes(read_model, bench.t0);
    CHECK(bench.engine->take_due(bench.t0).empty());
    CHECK(bench.engine->counters().unanswered == 1);
    CHECK(bench.engine->stats(bench.t0)["devices"]["2"]["ignored_dead"] == 1);
    bench.engine->apply_fault(parse_fault_spec("line-t@2:revive"));
    bench.engine->on_bytes(read_model, bench.t0 + 10ms);
    CHECK(bench.engine->take_due(bench.t0 + 10ms).size() == 1);
    CHECK_THROWS(bench.engine->apply_fault(parse_fault_spec("line-t@9:dead")));
}

TEST_CASE("device control reaches the model; unknown addresses are reported") {
    Bench bench(false);
    CHECK(bench.engine->device_control(2, "alarm 7", bench.t0).empty());
    CHECK(bench.engine->device_control(2, "bad", bench.t0) == "bad command");
    CHECK_FALSE(bench.engine->device_control(9, "alarm 7", bench.t0).empty());
    REQUIRE(bench.xeg->controls.size() == 2);
    CHECK(bench.xeg->controls[0] == "alarm 7");
}

TEST_CASE("reset_line forgets input and pending replies") {
    Bench bench(true);
    bench.engine->on_bytes(read_model, bench.t0);
    REQUIRE(bench.engine->next_output());
    bench.engine->reset_line();
    CHECK_FALSE(bench.engine->next_output());
    bench.engine->on_bytes(read_model, bench.t0 + 1ms);  // no collision after a reset
    CHECK(bench.engine->counters().collisions == 0);
}

}  // namespace fieldbridge::sim::runtime
