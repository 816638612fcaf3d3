// The broadcast unit's plan over the real profiles, and its line-time budget
// (northbound/targets/broadcast_plan.hpp, broadcast_budget.hpp).
#include <doctest/doctest.h>

#include <chrono>
#include <memory>
#include <vector>

#include "engine/profiles/profile_factory.hpp"
#include "northbound/targets/broadcast_budget.hpp"
#include "northbound/targets/broadcast_plan.hpp"

namespace fe = fieldbridge::engine;
namespace fn = fieldbridge::northbound;
namespace fp = fieldbridge::protocol;
using fp::ExceptionCode;
using namespace std::chrono_literals;

namespace {

/// Devices of one line with their profiles and (empty) images.
struct Line {
    std::vector<std::unique_ptr<fe::DeviceProfile>> profiles;
    fe::RegisterImage image;
    std::vector<fn::BroadcastMember> members;

    explicit Line(std::initializer_list<fe::DeviceType> types) {
        for (const fe::DeviceType type : types) {
            fe::ProfileOptions options;
            options.wtec_stroke = 20000;
            profiles.push_back(fe::make_profile(type, options));
        }
        for (const auto& profile : profiles) members.push_back(fn::BroadcastMember{profile.get(), &image, 0ms});
    }
    [[nodiscard]] fn::BroadcastPlan plan(const fp::Request& request) const { return fn::plan_broadcast(request, members); }
};

[[nodiscard]] const fp::Request& sent(const fn::BroadcastStep& step) {
    return std::get<fe::ModbusPayload>(step.payload).request;
}

}  // namespace

TEST_CASE("broadcast plan: each address gets the write only when every device on it takes it") {
    const Line line{fe::DeviceType::hiwin_xeg, fe::DeviceType::excd203mb, fe::DeviceType::wtec_ascii};
    // EXCD203MB station ID: protected (XEG: not its register) -> 0x01, nothing sent.
    CHECK(line.plan(fp::WriteSingleRegisterRequest{0x0020, 7}).refusal == ExceptionCode::illegal_function);
    CHECK(line.plan(fp::WriteSingleRegisterRequest{0x0020, 7}).steps.empty());
    // Out of range, half a pair, an XEG model code the manual does not list (0x0600 is
    // writable since issue 13, with the model codes only), nobody's register.
    CHECK(line.plan(fp::WriteSingleRegisterRequest{0x0012, 0xFFFF}).refusal == ExceptionCode::illegal_data_value);
    CHECK(line.plan(fp::WriteSingleRegisterRequest{0x0014, 1}).refusal == ExceptionCode::illegal_data_address);
    CHECK(line.plan(fp::WriteMultipleRegistersRequest{0x0600, {2}}).refusal == ExceptionCode::illegal_data_value);
    CHECK(line.plan(fp::WriteSingleRegisterRequest{0x7000, 1}).refusal == ExceptionCode::illegal_data_address);
    // The EXCD203MB's solm+ pair: to 0xFF only.
    const auto excd = line.plan(fp::WriteMultipleRegistersRequest{0x0014, {0, 4321}});
    REQUIRE_FALSE(excd.refusal);
    REQUIRE(excd.steps.size() == 1);
    CHECK(excd.steps[0].address == fieldbridge::core::BusAddress{0xFF});
    // The XEG's FC06 goes out as FC16 to address 0 (seed 001 §4.1).
    const auto xeg = line.plan(fp::WriteSingleRegisterRequest{0x0630, 1234});
    REQUIRE(xeg.steps.size() == 1);
    CHECK(xeg.steps[0].address == fieldbridge::core::BusAddress{0x00});
    CHECK(sent(xeg.steps[0]) == fp::Request{fp::WriteMultipleRegistersRequest{0x0630, {1234}}});
}

TEST_CASE("broadcast plan: devices on one address that disagree refuse the whole broadcast") {
    // A WTEC RTU gripper and an XEG both listen on 0: an XEG register the WTEC does
    // not have cannot be broadcast without reaching it.
    const Line line{fe::DeviceType::hiwin_xeg, fe::DeviceType::wtec_rtu};
    const auto plan = line.plan(fp::WriteMultipleRegistersRequest{0x0630, {1000, 5000, 1}});
    CHECK(plan.refusal);
    CHECK(plan.steps.empty());
    // A line without a Modbus device: nothing can be broadcast.
    const Line ascii{fe::DeviceType::wtec_ascii};
    CHECK(ascii.plan(fp::WriteSingleRegisterRequest{0x0100, 1}).refusal == ExceptionCode::illegal_function);
}

TEST_CASE("broadcast budget: at most the share of line time, one second's worth at once") {
    fn::BroadcastBudget budget(10);  // 100 ms per second
    const fe::TimePoint t0{};
    CHECK(budget.take(60ms, t0));
    CHECK(budget.take(60ms, t0));        // 40 ms left: goes out, the balance goes below 0
    CHECK_FALSE(budget.take(1ms, t0));   // -20 ms
    CHECK_FALSE(budget.take(1ms, t0 + 200ms));  // refilled 20 ms: at 0, still nothing
    CHECK(budget.take(60ms, t0 + 210ms));
    // A long quiet time fills it to one second's worth, not more.
    CHECK(budget.take(100ms, t0 + 100s));
    CHECK_FALSE(budget.take(1ms, t0 + 100s));
}

TEST_CASE("broadcast budget: a stop goes out over budget and the broadcasts after it pay for it") {
    fn::BroadcastBudget budget(10);  // 100 ms per second
    const fe::TimePoint t0{};
    CHECK(budget.take(150ms, t0));       // -50 ms
    CHECK_FALSE(budget.take(1ms, t0));
    budget.charge(50ms, t0);             // the stop: -100 ms
    CHECK_FALSE(budget.take(1ms, t0 + 900ms));  // refilled 90 ms: -10 ms
    CHECK(budget.take(1ms, t0 + 1100ms));       // +10 ms
}

TEST_CASE("broadcast budget: the debt has a floor, so a flood's end frees the budget within two seconds") {
    fn::BroadcastBudget budget(10);  // 100 ms per second
    const fe::TimePoint t0{};
    // An hour of stops charged at once: the balance stops at minus one second's worth.
    for (int i = 0; i < 36'000; ++i) budget.charge(100ms, t0);
    CHECK_FALSE(budget.take(1ms, t0 + 1000ms));  // refilled 100 ms: at 0
    CHECK(budget.available_at(t0 + 1000ms) > t0 + 1000ms);
    CHECK(budget.take(1ms, t0 + 1010ms));
}

TEST_CASE("broadcast budget: a broadcast that did not go out gives its share back") {
    fn::BroadcastBudget budget(10);
    const fe::TimePoint t0{};
    CHECK(budget.take(150ms, t0));  // -50 ms
    CHECK_FALSE(budget.take(1ms, t0));
    budget.refund(150ms, t0);       // refused by the line's queue after all: 100 ms
    CHECK(budget.take(1ms, t0));
    // A refund never fills it past its capacity.
    budget.refund(10s, t0);
    CHECK(budget.take(100ms, t0));
    CHECK_FALSE(budget.take(1ms, t0));
}

TEST_CASE("broadcast budget: available_at names the first instant take() succeeds") {
    const fe::TimePoint t0{};
    fn::BroadcastBudget early(10);
    fn::BroadcastBudget on_time(10);
    CHECK(early.available_at(t0) == t0);
    CHECK(early.take(130ms, t0));  // -30 ms: 300 ms of refill to get back to 0
    CHECK(on_time.take(130ms, t0));
    const fe::TimePoint at = early.available_at(t0);
    CHECK(at > t0 + 300ms);
    CHECK(at < t0 + 301ms);
    CHECK_FALSE(early.take(1ms, at - 1ns));
    CHECK(on_time.take(1ms, at));
}
