#include "engine_harness.hpp"

#include <asio/steady_timer.hpp>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cstdio>
#include <stdexcept>

#include "config/config_loader.hpp"

namespace fieldbridge::integration {

namespace fc = protocol::fc;
using engine::Clock;

EngineHarness::EngineHarness(std::string_view yaml)
    : work_(asio::make_work_guard(io_)), config_(config::load_config_string(yaml, "engine-it.yaml")) {
    engine::LogSink log;
    log.min_level = engine::LogLevel::warning;
    log.write = [this](engine::LogLevel level, std::string_view message) {
        std::string line = fmt::format("[{}] {}", engine::to_string(level), message);
        std::fprintf(stderr, "engine: %s\n", line.c_str());
        warnings_.push_back(std::move(line));
    };
    engine_ = std::make_unique<engine::Engine>(io_, *config_, log);
}

EngineHarness::~EngineHarness() {
    stop();
    engine_.reset();
    work_.reset();
    // Whatever the engine posted (answers, completions) runs before the context goes.
    io_.restart();
    io_.run_for(milliseconds{100});
}

void EngineHarness::start() { engine_->start(); }

void EngineHarness::stop() {
    if (!engine_) return;
    engine_->stop();
    run_for(milliseconds{20});
}

void EngineHarness::run_for(Duration duration) {
    // io_context::run(), as the daemon runs it, stopped by a timer: run_for() would
    // run one handler per call and look at the reactor after each, which the daemon
    // never does (the line benchmark's CPU figure counted those extra epoll_wait calls).
    if (io_.stopped()) io_.restart();
    asio::steady_timer stop_timer(io_, duration);
    stop_timer.async_wait([this](const asio::error_code& error) {
        if (!error) io_.stop();
    });
    io_.run();
    io_.restart();
}

bool EngineHarness::run_until(const std::function<bool()>& done, Duration timeout, Duration slice) {
    const auto deadline = Clock::now() + timeout;
    while (!done()) {
        if (Clock::now() >= deadline) return done();
        run_for(slice);
    }
    return true;
}

std::optional<protocol::Response> EngineHarness::request(engine::DeviceAgent& agent, const protocol::Request& request,
                                                         Duration timeout) {
    // Shared with the handler: it may run after this function gave up waiting.
    auto answer = std::make_shared<std::optional<protocol::Response>>();
    agent.request(request, [answer](const protocol::Response& response) { *answer = response; });
    run_until([&] { return answer->has_value(); }, timeout);
    return *answer;
}

std::optional<std::uint16_t> EngineHarness::read_register(engine::DeviceAgent& agent, std::uint16_t address) {
    const auto answer = request(agent, read_holding(address));
    if (!answer) return std::nullopt;
    const auto values = registers_of(*answer);
    if (values.size() != 1) return std::nullopt;
    return values.front();
}

engine::DeviceAgent& EngineHarness::device(std::string_view name) const {
    if (auto* agent = engine_->find_device(name)) return *agent;
    throw std::invalid_argument("no device named " + std::string(name) + " in the test configuration");
}

engine::LineWorker& EngineHarness::line(std::string_view name) const {
    for (const auto& entry : engine_->lines()) {
        if (entry.worker->config().name == name) return *entry.worker;
    }
    throw std::invalid_argument("no line named " + std::string(name) + " in the test configuration");
}

engine::LineWorker& EngineHarness::line_of(std::string_view device_name) const {
    return line(device(device_name).config().line_name);
}

const engine::DeviceStats& EngineHarness::stats(std::string_view device_name) const {
    const auto& agent = device(device_name);
    const engine::DeviceStats* stats = line_of(device_name).scheduler().stats(agent.config().index);
    if (stats == nullptr) throw std::logic_error("the scheduler does not know device " + std::string(device_name));
    return *stats;
}

protocol::Request read_holding(std::uint16_t address, std::uint16_t count) {
    return protocol::ReadRegistersRequest{fc::read_holding_registers, address, count};
}

protocol::Request read_input(std::uint16_t address, std::uint16_t count) {
    return protocol::ReadRegistersRequest{fc::read_input_registers, address, count};
}

protocol::Request write_register(std::uint16_t address, std::uint16_t value) {
    return protocol::WriteSingleRegisterRequest{address, value};
}

std::optional<protocol::ExceptionCode> exception_of(const protocol::Response& response) {
    if (const auto* exception = std::get_if<protocol::ExceptionResponse>(&response)) return exception->code;
    return std::nullopt;
}

std::vector<std::uint16_t> registers_of(const protocol::Response& response) {
    if (const auto* read = std::get_if<protocol::ReadRegistersResponse>(&response)) return read->values;
    return {};
}

std::string describe(const std::optional<protocol::Response>& response) {
    if (!response) return "no answer";
    if (const auto code = exception_of(*response)) {
        return fmt::format("exception 0x{:02X}", static_cast<unsigned>(*code));
    }
    if (const auto* read = std::get_if<protocol::ReadRegistersResponse>(&*response)) {
        return fmt::format("registers {}", read->values);
    }
    if (const auto* write = std::get_if<protocol::WriteSingleResponse>(&*response)) {
        return fmt::format("write echo 0x{:04X} = {}", write->address, write->value);
    }
    return "another response";
}

std::optional<std::uint16_t> good_value(const engine::DeviceAgent& agent, engine::Table table, std::uint16_t address) {
    const auto entry = agent.image().get(table, address);
    if (!entry || entry->quality != engine::Quality::good) return std::nullopt;
    return entry->value;
}

}  // namespace fieldbridge::integration
