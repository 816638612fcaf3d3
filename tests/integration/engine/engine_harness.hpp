#pragma once
/// @file engine_harness.hpp
/// The real line engine (engine::Engine) built from a YAML configuration through the
/// real loader, on an asio::io_context that the test runs in bounded slices. Every
/// wait has a timeout; the destructor stops the engine (completing whatever is
/// queued) before the io_context goes.
#include <asio/executor_work_guard.hpp>
#include <asio/io_context.hpp>
#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "config/config.hpp"
#include "engine/engine.hpp"
#include "protocol/modbus_pdu.hpp"

namespace fieldbridge::integration {

using engine::Duration;
using std::chrono::milliseconds;
using std::chrono::seconds;

class EngineHarness {
public:
    /// Loads @p yaml (throws config::ConfigError with every problem) and builds the
    /// engine; nothing is opened before start().
    explicit EngineHarness(std::string_view yaml);
    ~EngineHarness();
    EngineHarness(const EngineHarness&) = delete;
    EngineHarness& operator=(const EngineHarness&) = delete;

    void start();
    /// Stops the engine (idempotent) and runs the loop briefly so posted completions run.
    void stop();

    /// Runs the loop for @p duration.
    void run_for(Duration duration);
    /// Runs the loop until @p done returns true (checked every @p slice) or
    /// @p timeout passes; returns done()'s last value.
    bool run_until(const std::function<bool()>& done, Duration timeout, Duration slice = milliseconds{2});

    /// Sends @p request through @p agent and runs the loop until it is answered;
    /// nullopt when no answer came within @p timeout.
    std::optional<protocol::Response> request(engine::DeviceAgent& agent, const protocol::Request& request,
                                              Duration timeout = seconds{3});

    /// One holding register read through @p agent (max_age as configured); nullopt
    /// when the answer is an exception or does not come within 3 s.
    std::optional<std::uint16_t> read_register(engine::DeviceAgent& agent, std::uint16_t address);

    [[nodiscard]] engine::Engine& engine() noexcept { return *engine_; }
    [[nodiscard]] asio::io_context& io() noexcept { return io_; }
    /// The agent of the device named @p name; throws when unknown.
    [[nodiscard]] engine::DeviceAgent& device(std::string_view name) const;
    /// The worker of the line named @p name; throws when unknown.
    [[nodiscard]] engine::LineWorker& line(std::string_view name) const;
    /// The worker of the line that holds device @p name.
    [[nodiscard]] engine::LineWorker& line_of(std::string_view device_name) const;
    /// The scheduler's counters of device @p name.
    [[nodiscard]] const engine::DeviceStats& stats(std::string_view device_name) const;

    /// Log messages at warning and above, in order (also written to stderr).
    [[nodiscard]] const std::vector<std::string>& warnings() const noexcept { return warnings_; }

private:
    asio::io_context io_{1};  // one thread, as the daemon runs it (daemon.hpp)
    asio::executor_work_guard<asio::io_context::executor_type> work_;
    std::shared_ptr<const config::Config> config_;
    std::vector<std::string> warnings_;
    std::unique_ptr<engine::Engine> engine_;
};

// ---- requests and answers ---------------------------------------------------------

[[nodiscard]] protocol::Request read_holding(std::uint16_t address, std::uint16_t count = 1);
[[nodiscard]] protocol::Request read_input(std::uint16_t address, std::uint16_t count = 1);
[[nodiscard]] protocol::Request write_register(std::uint16_t address, std::uint16_t value);

/// The exception code of an exception response; nullopt for a normal response.
[[nodiscard]] std::optional<protocol::ExceptionCode> exception_of(const protocol::Response& response);
/// The registers of an FC03/FC04 response; empty for anything else.
[[nodiscard]] std::vector<std::uint16_t> registers_of(const protocol::Response& response);
/// "exception 0x0B", "registers [..]", "write echo ..." for failure messages.
[[nodiscard]] std::string describe(const std::optional<protocol::Response>& response);

/// The image value of @p address when its quality is good; nullopt otherwise.
[[nodiscard]] std::optional<std::uint16_t> good_value(const engine::DeviceAgent& agent, engine::Table table,
                                                      std::uint16_t address);

}  // namespace fieldbridge::integration
