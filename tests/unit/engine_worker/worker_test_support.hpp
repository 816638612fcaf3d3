#pragma once
// Helpers for the line worker tests that need no pseudo-terminal: bounded loop
// runners, transaction builders, a completion recorder and a log capture. The
// scripted device on a real pty is tests/integration/engine_worker/pty_device.hpp.
#include <doctest/doctest.h>

#include <asio/io_context.hpp>
#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "engine/line_worker.hpp"
#include "protocol/modbus_pdu.hpp"
#include "protocol/rtu_frame.hpp"
#include "run_until.hpp"

namespace worker_test {

namespace fe = fieldbridge::engine;
namespace fp = fieldbridge::protocol;
using namespace std::chrono_literals;
using fe::OutcomeStatus;
using fe::Priority;
using fe::Transaction;
using fp::Bytes;

using fieldbridge::test_support::run_for;
using fieldbridge::test_support::run_until;

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
    [[nodiscard]] const fe::Outcome& outcome(const std::string& tag) const {
        REQUIRE(calls(tag) == 1);
        return outcomes_.at(tag).front();
    }
    [[nodiscard]] OutcomeStatus status(const std::string& tag) const { return outcome(tag).status; }
    [[nodiscard]] std::size_t total() const { return order_.size(); }
    [[nodiscard]] const std::vector<std::string>& order() const { return order_; }

private:
    std::map<std::string, std::vector<fe::Outcome>> outcomes_;
    std::vector<std::string> order_;
};

/// Keeps every log line (level and text).
class LogCapture {
public:
    fe::LogSink sink(fe::LogLevel min_level = fe::LogLevel::info) {
        return fe::LogSink{[this](fe::LogLevel level, std::string_view text) {
                               lines_.emplace_back(level, std::string(text));
                           },
                           min_level};
    }
    [[nodiscard]] bool contains(fe::LogLevel level, const std::string& needle) const {
        for (const auto& [l, text] : lines_) {
            if (l == level && text.find(needle) != std::string::npos) return true;
        }
        return false;
    }
    [[nodiscard]] std::string dump() const {
        std::string out;
        for (const auto& [l, text] : lines_) out += std::string(fe::to_string(l)) + ": " + text + "\n";
        return out;
    }

private:
    std::vector<std::pair<fe::LogLevel, std::string>> lines_;
};

inline Transaction read_tx(std::uint8_t address, Priority priority, std::uint16_t reg = 0x0100,
                           std::uint16_t count = 2) {
    Transaction t;
    t.device = static_cast<fe::DeviceIndex>(address - 1);
    t.address = address;
    t.payload = fe::ModbusPayload{fp::ReadRegistersRequest{fp::fc::read_holding_registers, reg, count}};
    t.priority = priority;
    t.retry_allowed = true;
    return t;
}

inline Transaction write_tx(std::uint8_t address, std::uint16_t reg, std::uint16_t value) {
    Transaction t;
    t.device = static_cast<fe::DeviceIndex>(address - 1);
    t.address = address;
    t.payload = fe::ModbusPayload{fp::WriteSingleRegisterRequest{reg, value}};
    t.priority = Priority::command;
    return t;
}

inline Transaction write_multiple_tx(std::uint8_t address, std::uint16_t reg, std::vector<std::uint16_t> values) {
    Transaction t;
    t.device = static_cast<fe::DeviceIndex>(address - 1);
    t.address = address;
    t.payload = fe::ModbusPayload{fp::WriteMultipleRegistersRequest{reg, std::move(values)}};
    t.priority = Priority::command;
    return t;
}

inline Transaction tagged(Transaction t, Recorder& recorder, const std::string& tag) {
    t.on_done = recorder.done(tag);
    return t;
}

/// The values of an ok FC03/FC04 outcome.
inline std::vector<std::uint16_t> values_of(const fe::Outcome& outcome) {
    REQUIRE(outcome.status == OutcomeStatus::ok);
    const auto* response = std::get_if<fp::Response>(&outcome.reply);
    REQUIRE(response != nullptr);
    const auto* read = std::get_if<fp::ReadRegistersResponse>(response);
    REQUIRE(read != nullptr);
    return read->values;
}

}  // namespace worker_test
