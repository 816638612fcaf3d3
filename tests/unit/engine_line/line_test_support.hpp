#pragma once
// Helpers for the line engine tests: a fake time base, transaction builders, reply
// bytes, an on_done recorder and one-step drivers for the line master.
#include <doctest/doctest.h>

#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "engine/line_core.hpp"
#include "engine/line_delivery.hpp"
#include "engine/line_master.hpp"
#include "engine/line_scheduler.hpp"
#include "engine/transaction.hpp"
#include "protocol/modbus_pdu.hpp"
#include "protocol/rtu_frame.hpp"
#include "protocol/wtec_ascii_commands.hpp"
#include "protocol/wtec_ascii_frame.hpp"

namespace line_test {

namespace fe = fieldbridge::engine;
namespace fp = fieldbridge::protocol;
namespace wtec = fieldbridge::protocol::wtec;
using namespace std::chrono_literals;
using fe::Duration;
using fe::Priority;
using fe::TimePoint;
using fe::Transaction;
using fp::Bytes;

/// Fake time origin: far from the clock's epoch so "last activity = epoch" is old.
inline const TimePoint t0 = TimePoint{} + std::chrono::hours{1};

/// Counts on_done calls per tag and keeps the outcomes.
class Recorder {
public:
    std::function<void(const fe::Outcome&)> done(const std::string& tag) {
        return [this, tag](const fe::Outcome& outcome) {
            outcomes_[tag].push_back(outcome);
            order_.push_back(tag);
        };
    }
    [[nodiscard]] std::size_t calls(const std::string& tag) const {
        const auto it = outcomes_.find(tag);
        return it == outcomes_.end() ? 0 : it->second.size();
    }
    /// The only outcome of @p tag (checks it was called exactly once).
    [[nodiscard]] const fe::Outcome& outcome(const std::string& tag) const {
        REQUIRE(calls(tag) == 1);
        return outcomes_.at(tag).front();
    }
    [[nodiscard]] fe::OutcomeStatus status(const std::string& tag) const { return outcome(tag).status; }
    [[nodiscard]] const std::vector<std::string>& order() const { return order_; }
    [[nodiscard]] std::size_t total() const { return order_.size(); }

private:
    std::map<std::string, std::vector<fe::Outcome>> outcomes_;
    std::vector<std::string> order_;
};

/// FC03/FC04 read of @p count registers at @p address.
inline Transaction read_tx(fe::DeviceIndex device, std::uint8_t address, Priority priority,
                           std::uint16_t reg = 0x0300, std::uint16_t count = 2,
                           std::uint8_t function = fp::fc::read_input_registers) {
    Transaction t;
    t.device = device;
    t.address = address;
    t.payload = fe::ModbusPayload{fp::ReadRegistersRequest{function, reg, count}};
    t.priority = priority;
    t.retry_allowed = true;
    return t;
}

/// One character at 115200 8N1 (11 bits).
inline constexpr std::chrono::nanoseconds tc{86'806};

// XEG id 2: read model 0x0600 -> 0x0A20 (seed 001, appendix 1; tests/vectors/vectors.yaml).
inline const Bytes read_model_request = {0x02, 0x03, 0x06, 0x00, 0x00, 0x01, 0x84, 0xB1};
inline const Bytes read_model_reply = {0x02, 0x03, 0x02, 0x0A, 0x20, 0xFB, 0x3C};

inline Transaction read_model() {
    return read_tx(0, 2, Priority::poll, 0x0600, 1, fp::fc::read_holding_registers);
}

/// FC06 command.
inline Transaction write_tx(fe::DeviceIndex device, std::uint8_t address, std::uint16_t reg,
                            std::uint16_t value) {
    Transaction t;
    t.device = device;
    t.address = address;
    t.payload = fe::ModbusPayload{fp::WriteSingleRegisterRequest{reg, value}};
    t.priority = Priority::command;
    return t;
}

inline Transaction ascii_tx(fe::DeviceIndex device, std::uint8_t address, wtec::Command command,
                            Priority priority = Priority::poll) {
    Transaction t;
    t.device = device;
    t.address = address;
    t.payload = fe::AsciiPayload{std::move(command)};
    t.priority = priority;
    return t;
}

inline Transaction tagged(Transaction t, Recorder& recorder, const std::string& tag) {
    t.on_done = recorder.done(tag);
    return t;
}

inline Bytes rtu(std::uint8_t address, const Bytes& pdu) { return fp::encode_rtu(address, pdu); }

inline Bytes read_reply(std::uint8_t address, std::vector<std::uint16_t> values,
                        std::uint8_t function = fp::fc::read_input_registers) {
    return rtu(address, fp::encode_response(fp::ReadRegistersResponse{function, std::move(values)}));
}

inline Bytes text_bytes(const std::string& text) { return Bytes(text.begin(), text.end()); }

inline Bytes ascii_frame(std::uint8_t address, char command, std::string data) {
    return text_bytes(wtec::encode_frame(wtec::AsciiFrame{address, command, std::move(data)}));
}

inline Bytes concat(std::initializer_list<Bytes> parts) {
    Bytes out;
    for (const auto& part : parts) out.insert(out.end(), part.begin(), part.end());
    return out;
}

// ---- the scheduler, delivered ----------------------------------------------------

/// A LineScheduler whose collected completions and health changes are delivered
/// after every call, as the line core's shell delivers them after every transition
/// (LineDelivery: health changes first, a handler may submit).
class Scheduler {
public:
    explicit Scheduler(fe::SchedulerConfig config = {"A"}, fe::LogSink log = {})
        : delivery_(config.line_name, log), scheduler_(std::move(config), std::move(log)) {}

    void add_device(fe::DeviceIndex device, fe::DeviceLimits limits, std::string name = {}) {
        scheduler_.add_device(device, limits, std::move(name));
    }
    void update_device(fe::DeviceIndex device, fe::DeviceLimits limits) { scheduler_.update_device(device, limits); }
    void set_health_callback(fe::HealthCallback callback) { delivery_.set_health_callback(std::move(callback)); }

    void remove_device(fe::DeviceIndex device, fe::OutcomeStatus status, TimePoint now) {
        scheduler_.remove_device(device, status, now);
        deliver();
    }
    void submit(Transaction transaction, TimePoint now) {
        scheduler_.submit(std::move(transaction), now);
        deliver();
    }
    std::optional<Transaction> next(TimePoint now) {
        std::optional<Transaction> picked = scheduler_.next(now);
        deliver();
        return picked;
    }
    void finished(Transaction transaction, const fe::Outcome& outcome, TimePoint now) {
        scheduler_.finished(std::move(transaction), outcome, now);
        deliver();
    }
    void line_opened(TimePoint now) { scheduler_.line_opened(now); }
    void expire(TimePoint now) {
        scheduler_.expire(now);
        deliver();
    }
    void cancel_all(fe::OutcomeStatus status, TimePoint now) {
        scheduler_.cancel_all(status, now);
        deliver();
    }
    void turn_away(Transaction transaction, fe::OutcomeStatus status, TimePoint now) {
        scheduler_.turn_away(std::move(transaction), status, now);
        deliver();
    }

    [[nodiscard]] std::optional<TimePoint> next_wakeup(TimePoint now) const { return scheduler_.next_wakeup(now); }
    [[nodiscard]] bool has_device(fe::DeviceIndex device) const noexcept { return scheduler_.has_device(device); }
    [[nodiscard]] bool online(fe::DeviceIndex device) const noexcept { return scheduler_.online(device); }
    [[nodiscard]] const fe::DeviceStats* stats(fe::DeviceIndex device) const noexcept {
        return scheduler_.stats(device);
    }
    [[nodiscard]] std::size_t queued(fe::DeviceIndex device) const noexcept { return scheduler_.queued(device); }
    [[nodiscard]] std::size_t queued() const noexcept { return scheduler_.queued(); }
    [[nodiscard]] std::optional<TimePoint> probe_due(fe::DeviceIndex device) const noexcept {
        return scheduler_.probe_due(device);
    }
    [[nodiscard]] const fe::SchedulerConfig& config() const noexcept { return scheduler_.config(); }

private:
    void deliver() { delivery_.deliver(scheduler_); }

    fe::LineDelivery delivery_;
    fe::LineScheduler scheduler_;
};

// ---- master drivers -------------------------------------------------------------

inline TimePoint expect_wait(fe::LineMaster& master, TimePoint now) {
    auto action = master.next_action(now);
    REQUIRE(std::holds_alternative<fe::line_action::Wait>(action));
    return std::get<fe::line_action::Wait>(action).until;
}

inline Bytes expect_write(fe::LineMaster& master, TimePoint now) {
    auto action = master.next_action(now);
    REQUIRE(std::holds_alternative<fe::line_action::Write>(action));
    const auto view = std::get<fe::line_action::Write>(action).bytes;
    return Bytes(view.begin(), view.end());
}

inline fe::line_action::Finished expect_finished(fe::LineMaster& master, TimePoint now) {
    auto action = master.next_action(now);
    REQUIRE(std::holds_alternative<fe::line_action::Finished>(action));
    return std::move(std::get<fe::line_action::Finished>(action));
}

/// Starts @p t at @p now, waits for the silence, writes at the earliest moment.
/// Returns the request bytes; the write time is in @p written_at.
inline Bytes send(fe::LineMaster& master, Transaction t, TimePoint now, TimePoint& written_at) {
    master.start(std::move(t), now);
    auto action = master.next_action(now);
    if (std::holds_alternative<fe::line_action::Wait>(action)) {
        now = std::get<fe::line_action::Wait>(action).until;
        action = master.next_action(now);
    }
    REQUIRE(std::holds_alternative<fe::line_action::Write>(action));
    const auto view = std::get<fe::line_action::Write>(action).bytes;
    Bytes bytes(view.begin(), view.end());
    master.on_written(now);
    written_at = now;
    return bytes;
}

/// The 115200 8N1 configuration of the product's devices with the config defaults.
inline fe::LineTimingConfig default_line() { return fe::LineTimingConfig{}; }

}  // namespace line_test
