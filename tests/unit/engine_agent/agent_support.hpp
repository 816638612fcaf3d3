#pragma once
// Helpers of the device-agent tests: a fake line that records the transactions an
// agent submits and lets the test complete them, replies built with the protocol
// codecs (as the line master would deliver them), and bounded loop runners.

#include <doctest/doctest.h>

#include <asio/executor_work_guard.hpp>
#include <asio/io_context.hpp>
#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include "engine/device_agent.hpp"
#include "engine/profiles/profile_factory.hpp"
#include "protocol/modbus_pdu.hpp"
#include "protocol/wtec_ascii_commands.hpp"
#include "run_until.hpp"

namespace fbt {

namespace fe = fieldbridge::engine;
namespace fp = fieldbridge::protocol;
namespace fw = fieldbridge::protocol::wtec;
using namespace std::chrono_literals;
using fe::Clock;

// ---- the fake line ----------------------------------------------------------------

/// Payloads carry no operator==: the same request or command.
inline bool same(const fe::Payload& a, const fe::Payload& b) {
    if (a.index() != b.index()) return false;
    if (const auto* m = std::get_if<fe::ModbusPayload>(&a)) return m->request == std::get<fe::ModbusPayload>(b).request;
    return std::get<fe::AsciiPayload>(a).command == std::get<fe::AsciiPayload>(b).command;
}

/// Records every submission; the test completes them (or the line completes them
/// inside submit() when `complete_inline` is set, as the scheduler does for a full
/// queue or a passed deadline).
struct FakeLine {
    struct Sent {
        fe::Transaction transaction;
        fe::TimePoint at;
        bool done = false;
    };
    std::deque<Sent> sent;  ///< a deque: references stay valid while more are submitted
    std::optional<fe::OutcomeStatus> complete_inline;

    [[nodiscard]] fe::SubmitFunction submitter() {
        return [this](fe::Transaction t) { submit(std::move(t)); };
    }

    void submit(fe::Transaction t) {
        sent.push_back({std::move(t), Clock::now(), false});
        if (complete_inline) {
            finish(sent.size() - 1, fe::Outcome{*complete_inline, {}, Clock::now(), 0});
        }
    }

    /// Completes submission @p i (exactly once, like the scheduler).
    void finish(std::size_t i, const fe::Outcome& outcome) {
        REQUIRE(i < sent.size());
        REQUIRE_FALSE(sent[i].done);
        sent[i].done = true;
        // Copy: on_done may submit again, which grows `sent`.
        const auto on_done = sent[i].transaction.on_done;
        REQUIRE(on_done);
        on_done(outcome);
    }
    void reply(std::size_t i, fe::Reply reply) {
        finish(i, fe::Outcome{fe::OutcomeStatus::ok, std::move(reply), Clock::now(), 1});
    }
    void fail(std::size_t i, fe::OutcomeStatus status) { finish(i, fe::Outcome{status, {}, Clock::now(), 1}); }

    [[nodiscard]] const fe::Transaction& at(std::size_t i) const { return sent.at(i).transaction; }
    [[nodiscard]] std::size_t open_count() const {
        std::size_t n = 0;
        for (const Sent& s : sent) n += s.done ? 0 : 1;
        return n;
    }
    /// Indexes of the submissions whose payload is @p payload.
    [[nodiscard]] std::vector<std::size_t> all_of(const fe::Payload& payload) const {
        std::vector<std::size_t> out;
        for (std::size_t i = 0; i < sent.size(); ++i) {
            if (same(sent[i].transaction.payload, payload)) out.push_back(i);
        }
        return out;
    }
    [[nodiscard]] std::size_t count(const fe::Payload& payload) const { return all_of(payload).size(); }
    /// The open submission of @p payload; fails the test when there is none.
    [[nodiscard]] std::size_t open(const fe::Payload& payload) const {
        for (std::size_t i = 0; i < sent.size(); ++i) {
            if (!sent[i].done && same(sent[i].transaction.payload, payload)) return i;
        }
        FAIL("no open submission of that payload");
        return 0;
    }
    [[nodiscard]] bool has_open(const fe::Payload& payload) const {
        for (const Sent& s : sent) {
            if (!s.done && same(s.transaction.payload, payload)) return true;
        }
        return false;
    }
};

// ---- payloads and replies ---------------------------------------------------------

inline fe::Payload modbus(fp::Request request) { return fe::ModbusPayload{std::move(request)}; }
inline fe::Payload ascii(fw::Command command) { return fe::AsciiPayload{std::move(command)}; }
inline fe::Payload read_input(std::uint16_t address, std::uint16_t count) {
    return modbus(fp::ReadRegistersRequest{fp::fc::read_input_registers, address, count});
}
inline fe::Payload read_holding(std::uint16_t address, std::uint16_t count) {
    return modbus(fp::ReadRegistersRequest{fp::fc::read_holding_registers, address, count});
}
inline fe::Payload read_discrete(std::uint16_t address, std::uint16_t count) {
    return modbus(fp::ReadBitsRequest{fp::fc::read_discrete_inputs, address, count});
}
inline const fp::Request& request_of(const fe::Transaction& t) { return std::get<fe::ModbusPayload>(t.payload).request; }

inline fp::Bytes bytes(std::string_view hex) {
    fp::Bytes out;
    std::string digits;
    for (const char c : hex) {
        if (c != ' ') digits.push_back(c);
    }
    REQUIRE(digits.size() % 2 == 0);
    for (std::size_t i = 0; i < digits.size(); i += 2) {
        out.push_back(static_cast<std::uint8_t>(std::stoul(digits.substr(i, 2), nullptr, 16)));
    }
    return out;
}

/// The reply PDU @p hex decoded as the answer to @p t's request, as the line master
/// would deliver it (fails the test when the PDU does not answer the request).
inline fe::Reply pdu_reply(const fe::Transaction& t, std::string_view hex) {
    const fp::Bytes pdu = bytes(hex);
    const auto decoded = fp::decode_response(pdu, request_of(t));
    REQUIRE(decoded.complete());
    return fe::Reply{decoded.value};
}
/// @p response encoded and decoded against @p t's request.
inline fe::Reply encoded_reply(const fe::Transaction& t, const fp::Response& response) {
    const fp::Bytes pdu = fp::encode_response(response);
    const auto decoded = fp::decode_response(pdu, request_of(t));
    REQUIRE(decoded.complete());
    return fe::Reply{decoded.value};
}
inline fe::Reply registers_reply(const fe::Transaction& t, std::vector<std::uint16_t> values) {
    return encoded_reply(t, fp::ReadRegistersResponse{fp::function_of(request_of(t)), std::move(values)});
}
inline fe::Reply bits_reply(const fe::Transaction& t, std::vector<bool> bits) {
    return encoded_reply(t, fp::ReadBitsResponse{fp::function_of(request_of(t)), std::move(bits)});
}
inline fe::Reply exception_reply(const fe::Transaction& t, fp::ExceptionCode code) {
    return encoded_reply(t, fp::ExceptionResponse{fp::function_of(request_of(t)), code});
}
/// The echo a device sends for an FC16 write.
inline fe::Reply fc16_ack(const fe::Transaction& t) {
    const auto& w = std::get<fp::WriteMultipleRegistersRequest>(request_of(t));
    return encoded_reply(t, fp::WriteMultipleResponse{fp::fc::write_multiple_registers, w.address,
                                                      static_cast<std::uint16_t>(w.values.size())});
}
/// @p reply to @p t's ASCII command, through the frame codec (address @p address).
inline fe::Reply ascii_reply(const fe::Transaction& t, const fw::Reply& reply) {
    const auto& command = std::get<fe::AsciiPayload>(t.payload).command;
    const auto frame = fw::encode_reply(t.address, command, reply);
    const auto decoded = fw::decode_reply(t.address, command, frame);
    REQUIRE(decoded.complete());
    return fe::Reply{decoded.value};
}

// ---- the loop --------------------------------------------------------------------

using fieldbridge::test_support::run_for;
using fieldbridge::test_support::run_until;

// ---- an agent on the fake line ---------------------------------------------------

struct Answers {
    std::vector<fp::Response> got;
    [[nodiscard]] fe::ResponseHandler handler() {
        return [this](const fp::Response& r) { got.push_back(r); };
    }
};

struct Logs {
    std::vector<std::pair<fe::LogLevel, std::string>> lines;
    [[nodiscard]] fe::LogSink sink() {
        return fe::LogSink{[this](fe::LogLevel level, std::string_view text) { lines.emplace_back(level, text); },
                           fe::LogLevel::debug};
    }
    [[nodiscard]] std::size_t count(fe::LogLevel level, std::string_view part) const {
        std::size_t n = 0;
        for (const auto& [l, text] : lines) n += (l == level && text.find(part) != std::string::npos) ? 1 : 0;
        return n;
    }
};

inline fe::PollPeriods test_periods() {
    fe::PollPeriods p;
    p.fast = 20ms;
    p.slow = 400ms;
    p.motion = 5ms;
    return p;
}

inline fe::DeviceAgentConfig test_config() {
    fe::DeviceAgentConfig c;
    c.name = "gripper1";
    c.line_name = "bus0";
    c.index = 3;
    c.address = fieldbridge::core::BusAddress{7};
    c.max_age = 0ms;
    c.command_ttl = 300ms;
    c.delay_before_command = 4ms;
    c.motion_period = test_periods().motion;
    c.startup_retry = 1s;
    return c;
}

/// An agent that does not poll: only the requests of the test reach the line.
inline fe::DeviceAgentConfig quiet(fe::Duration max_age = 0ms) {
    fe::DeviceAgentConfig c = test_config();
    c.polling = false;
    c.max_age = max_age;
    return c;
}

/// An io_context kept alive, a fake line, and one agent of @p type on it.
struct Rig {
    asio::io_context io;
    asio::executor_work_guard<asio::io_context::executor_type> work = asio::make_work_guard(io);
    FakeLine line;
    Logs logs;
    Answers answers;
    std::vector<fe::DeviceNotice> notices;
    std::unique_ptr<fe::DeviceAgent> agent;

    explicit Rig(fe::DeviceType type, fe::DeviceAgentConfig config = test_config(),
                 fe::ProfileOptions options = default_options()) {
        options.address = config.address;
        agent = std::make_unique<fe::DeviceAgent>(io, std::move(config), fe::make_profile(type, options),
                                                  line.submitter(), logs.sink());
        agent->set_notice_callback([this](const fe::DeviceNotice& n) { notices.push_back(n); });
    }
    static fe::ProfileOptions default_options() {
        fe::ProfileOptions o;
        o.poll = test_periods();
        o.wtec_stroke = 10000;
        return o;
    }

    void request(const fp::Request& r) { agent->request(r, answers.handler()); }
    /// Runs the loop until @p n answers arrived (fails the test after the timeout).
    void await_answers(std::size_t n) {
        REQUIRE(run_until(io, [&] { return answers.got.size() >= n; }));
    }
    /// Runs the loop until at least @p n submissions were made.
    void await_sent(std::size_t n) {
        REQUIRE(run_until(io, [&] { return line.sent.size() >= n; }));
    }
    [[nodiscard]] const fp::Response& last_answer() const {
        REQUIRE_FALSE(answers.got.empty());
        return answers.got.back();
    }
};

inline fp::Response exception(std::uint8_t function, fp::ExceptionCode code) {
    return fp::ExceptionResponse{function, code};
}

}  // namespace fbt
