#pragma once
// Fakes and a harness for driving fieldbridge::daemon::Daemon in unit tests: a
// recording ServiceManager, a scripted Component, and a loop guard so that a
// broken daemon fails the test instead of hanging it.

#include <chrono>
#include <functional>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <asio/post.hpp>
#include <asio/steady_timer.hpp>
#include <doctest/doctest.h>
#include <spdlog/sinks/ostream_sink.h>

#include "daemon/component.hpp"
#include "daemon/daemon.hpp"
#include "daemon/logging.hpp"
#include "daemon/service_manager.hpp"

namespace fieldbridge::daemon::testing {

[[nodiscard]] inline bool starts_with(std::string_view text, std::string_view prefix) {
    return text.substr(0, prefix.size()) == prefix;
}

[[nodiscard]] inline std::shared_ptr<config::Config> config_with(std::size_t lines, std::size_t devices_per_line) {
    auto built = std::make_shared<config::Config>();
    built->gateway.id = "test";
    built->lines.resize(lines);
    for (auto& line : built->lines) {
        line.devices.resize(devices_per_line);
    }
    return built;
}

/// Records every notification; on_notify lets a test react (on the loop thread).
class FakeServiceManager final : public ServiceManager {
public:
    std::vector<std::string> messages;
    std::optional<std::chrono::microseconds> watchdog;
    std::function<void(const std::string&)> on_notify;

    void notify(std::string_view state) noexcept override {
        messages.emplace_back(state);
        if (on_notify) {
            on_notify(messages.back());
        }
    }
    [[nodiscard]] std::optional<std::chrono::microseconds> watchdog_timeout() const override { return watchdog; }

    [[nodiscard]] std::size_t count(std::string_view prefix) const {
        std::size_t n = 0;
        for (const auto& message : messages) {
            n += starts_with(message, prefix) ? 1U : 0U;
        }
        return n;
    }
    /// The messages other than watchdog pings, in order.
    [[nodiscard]] std::vector<std::string> without_pings() const {
        std::vector<std::string> kept;
        for (const auto& message : messages) {
            if (message != "WATCHDOG=1") {
                kept.push_back(message);
            }
        }
        return kept;
    }
};

/// A component that records what the daemon asks of it.
class FakeComponent final : public Component {
public:
    FakeComponent(std::string name, std::vector<std::string>& events) : name_(std::move(name)), events_(events) {}

    bool needs_ready_ticket = false;
    bool needs_stop_ticket = false;
    bool fails_to_start = false;
    CompletionBarrier::Ticket ready;
    CompletionBarrier::Ticket finished;
    std::vector<std::shared_ptr<const config::Config>> applied;
    std::shared_ptr<const config::Config> started_with;

    [[nodiscard]] std::string name() const override { return name_; }
    void start(StartContext& context) override {
        events_.push_back("start " + name_);
        started_with = context.config();
        if (fails_to_start) {
            throw std::runtime_error("port /dev/ttyUSB7 is busy");
        }
        if (needs_ready_ticket) {
            ready = context.expect_ready(name_ + " listener");
        }
    }
    void stop(StopContext& context) override {
        events_.push_back("stop " + name_);
        if (needs_stop_ticket) {
            finished = context.expect_finished(name_ + " transaction in flight");
        }
    }
    /// Non-empty: prepare() refuses every reload with this reason.
    std::string refuses_prepare;
    void prepare(const config::Config& /*next*/) override {
        if (!refuses_prepare.empty()) throw std::runtime_error(refuses_prepare);
    }
    void abandon() noexcept override { events_.push_back("abandon " + name_); }
    void apply(std::shared_ptr<const config::Config> config) override {
        events_.push_back("apply " + name_);
        applied.push_back(std::move(config));
    }

private:
    std::string name_;
    std::vector<std::string>& events_;
};

/// One daemon with fakes around it. Configure the public members, then create()
/// and run().
struct Harness {
    FakeServiceManager manager;
    std::ostringstream log_text;
    std::shared_ptr<spdlog::logger> logger =
        make_logger("test", std::make_shared<spdlog::sinks::ostream_sink_st>(log_text), LogFormat::journal);
    std::shared_ptr<const config::Config> initial = config_with(2, 2);
    /// What SIGHUP loads; by default the initial configuration again.
    ConfigLoader loader;
    int loads = 0;
    DaemonOptions options;
    std::unique_ptr<Daemon> daemon;
    std::vector<std::string> events;
    /// Bound on a whole test's loop: a daemon that never stops fails the test.
    std::chrono::milliseconds guard{10'000};

    Harness() {
        options.config_file = "gw.yaml";
        options.status_period = std::chrono::hours{1};
        options.stop_timeout = std::chrono::seconds{10};
    }

    Daemon& create() {
        ConfigLoader counting = [this](const std::filesystem::path& file) {
            ++loads;
            return loader ? loader(file) : initial;
        };
        daemon = std::make_unique<Daemon>(options, initial, std::move(counting), manager, logger);
        return *daemon;
    }

    /// Posts @p action to the loop (tests react to notifications this way, never
    /// re-entering the daemon from inside its own notify call).
    void later(std::function<void()> action) const { asio::post(daemon->context(), std::move(action)); }

    [[nodiscard]] int run() {
        asio::steady_timer guard_timer(daemon->context(), guard);
        bool guard_fired = false;
        guard_timer.async_wait([&](const std::error_code& error) {
            if (!error) {
                guard_fired = true;
                daemon->request_stop("test guard");
                daemon->request_stop("test guard");
            }
        });
        const int code = daemon->run();
        CHECK_FALSE(guard_fired);
        return code;
    }

    [[nodiscard]] bool logged(std::string_view text) const { return log_text.str().find(text) != std::string::npos; }
};

}  // namespace fieldbridge::daemon::testing
