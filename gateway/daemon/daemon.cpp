#include "daemon/daemon.hpp"

#include <pthread.h>
#include <sched.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <exception>
#include <thread>
#include <stdexcept>
#include <system_error>
#include <utility>

#include <asio/post.hpp>

#include "config/diagnostic.hpp"
#include "core/error.hpp"
#include "daemon/config_summary.hpp"
#include "daemon/exit_codes.hpp"
#include "daemon/logging.hpp"
#include "daemon/watchdog.hpp"

namespace fieldbridge::daemon {

namespace {

[[nodiscard]] std::string join(const std::vector<std::string>& names) {
    std::string text;
    for (const auto& name : names) {
        text += (text.empty() ? "" : ", ") + name;
    }
    return text;
}

[[nodiscard]] const char* signal_name(int signal_number) noexcept {
    switch (signal_number) {
        case SIGTERM:
            return "SIGTERM";
        case SIGINT:
            return "SIGINT";
        case SIGHUP:
            return "SIGHUP";
        default:
            return "a signal";
    }
}

/// "RELOADING=1" with the time of the request: systemd 253+ (Type=notify-reload)
/// needs MONOTONIC_USEC= with it to tell this reload from an older one, and older
/// managers ignore it. steady_clock is CLOCK_MONOTONIC on Linux, the clock
/// sd_notify(3) asks for.
[[nodiscard]] std::string reloading_message() {
    const auto now = std::chrono::duration_cast<std::chrono::microseconds>(
        std::chrono::steady_clock::now().time_since_epoch());
    return "RELOADING=1\nMONOTONIC_USEC=" + std::to_string(now.count());
}

}  // namespace

Daemon::Daemon(DaemonOptions options, std::shared_ptr<const config::Config> initial, ConfigLoader load,
               ServiceManager& manager, std::shared_ptr<spdlog::logger> logger)
    : options_(std::move(options)),
      config_(std::move(initial)),
      load_(std::move(load)),
      manager_(manager),
      logger_(std::move(logger)),
      signals_(io_, SIGTERM, SIGINT, SIGHUP),
      stop_timer_(io_),
      status_refresh_(io_, options_.status_period, [this] { publish_status(false); }),
      readiness_([this] { asio::post(io_, [this] { on_ready(); }); }) {
    if (!config_) {
        throw core::InvalidArgument("Daemon: no initial configuration");
    }
    status_.add([this] { return phase_note(); });
    status_.add([this] { return describe_inventory(*config_); });
}

Daemon::~Daemon() {
    // A reload still reading the file: its result is dropped with the loop.
    if (loading_.joinable()) loading_.join();
}

void Daemon::add_component(Component& component) {
    if (ran_) {
        throw std::logic_error("Daemon: component '" + component.name() + "' added after run()");
    }
    components_.push_back(&component);
}

void Daemon::add_status(StatusContributor contributor) { status_.add(std::move(contributor)); }

int Daemon::run() {
    if (ran_) {
        throw std::logic_error("Daemon::run() called twice");
    }
    ran_ = true;
    apply_log_level();
    logger_->info("starting gateway '{}' with {} ({})", config_->gateway.id, options_.config_file.string(),
                  describe_config(*config_));

    wait_for_signal();
    if (const auto interval = watchdog_ping_interval(manager_.watchdog_timeout())) {
        logger_->info("systemd watchdog enabled: pinging every {} ms",
                      std::chrono::duration<double, std::milli>(*interval).count());
        watchdog_.emplace(io_, *interval, [this] { notify("WATCHDOG=1"); });
        watchdog_->start(true);
    }
    status_refresh_.start(false);
    asio::post(io_, [this] { start_components(); });

    try {
        io_.run();
    } catch (const std::exception& error) {
        // A try/catch wall around every handler: an exception escaping a duty
        // leaves its component in an unknown state, so the process ends and
        // systemd's Restart=on-failure brings it back.
        logger_->critical("internal error, exiting: {}", error.what());
        manager_.notify("STOPPING=1");
        return exit_failure;
    }
    return exit_code_;
}

void Daemon::wait_for_signal() {
    signals_.async_wait([this](const std::error_code& error, int signal_number) {
        if (error || phase_ == Phase::stopped) {
            return;
        }
        on_signal(signal_number);
        if (phase_ != Phase::stopped) {
            wait_for_signal();
        }
    });
}

void Daemon::on_signal(int signal_number) {
    if (signal_number == SIGHUP) {
        logger_->info("SIGHUP received: reloading the configuration");
        request_reload();
    } else {
        request_stop(std::string(signal_name(signal_number)) + " received");
    }
}

void Daemon::start_components() {
    if (phase_ != Phase::starting) {
        return;
    }
    for (auto* component : components_) {
        try {
            StartContext context(config_, readiness_);
            logger_->debug("starting {}", component->name());
            component->start(context);
            ++started_;
        } catch (const std::exception& error) {
            fail("cannot start " + component->name() + ": " + error.what());
            return;
        }
    }
    // "starting, waiting for ..." names what READY=1 still waits for.
    publish_status(true);
    readiness_.arm();
}

void Daemon::on_ready() {
    if (phase_ != Phase::starting) {
        return;
    }
    phase_ = Phase::running;
    const auto status = status_.take_if_changed(true);
    notify("READY=1\nSTATUS=" + status.value_or(""));
    logger_->info("ready: {}", status.value_or(""));
    if (reload_pending_) {
        reload_pending_ = false;
        reload();
    }
}

void Daemon::request_reload() {
    switch (phase_) {
        case Phase::starting:
            logger_->info("reload requested during start-up: it runs once the gateway is ready");
            reload_pending_ = true;
            return;
        case Phase::stopping:
        case Phase::stopped:
            logger_->info("reload ignored: the gateway is stopping");
            return;
        case Phase::running:
            reload();
            return;
    }
}

namespace {

double milliseconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

/// CPU time the calling thread has used, in milliseconds. A reload's apply is
/// reported both ways: the wall time is what the loop was held for, the CPU time what
/// the apply itself cost (the difference is the OS running something else meanwhile).
double thread_cpu_ms() {
    timespec now{};
    (void)::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
    return static_cast<double>(now.tv_sec) * 1e3 + static_cast<double>(now.tv_nsec) / 1e6;
}

}  // namespace

void Daemon::reload() {
    if (loading_.joinable()) {
        // A reload is being read: read the file once more when it is done (the newest
        // file wins; two readers would race).
        reload_again_ = true;
        return;
    }
    notify(reloading_message());
    logger_->debug("re-reading {}", options_.config_file.string());
    // The file is read and validated off the loop, so the lines, TCP clients and MQTT
    // keep running meanwhile; only the difference is applied on the loop (finish_reload).
    // It runs at idle priority (SCHED_IDLE): on a busy two-core box the parser would
    // otherwise take CPU time from the line workers and the loop for the tens of
    // milliseconds a large file takes, and a line would idle meanwhile.
    loading_ = std::thread([this, file = options_.config_file] {
        const sched_param idle{};
        (void)::pthread_setschedparam(::pthread_self(), SCHED_IDLE, &idle);
        const auto start = std::chrono::steady_clock::now();
        std::shared_ptr<const config::Config> next;
        std::exception_ptr error;
        try {
            next = load_(file);
        } catch (...) {
            error = std::current_exception();
        }
        const auto read_ms = milliseconds_since(start);
        asio::post(io_, [this, next = std::move(next), error, read_ms]() mutable {
            finish_reload(std::move(next), error, read_ms);
        });
    });
}

void Daemon::finish_reload(std::shared_ptr<const config::Config> next, std::exception_ptr error, double read_ms) {
    if (loading_.joinable()) loading_.join();
    if (phase_ != Phase::running) {
        logger_->info("reload abandoned: the gateway is stopping");
        return;
    }
    const auto& file = options_.config_file;
    try {
        if (error) std::rethrow_exception(error);
    } catch (const config::ConfigError& rejected) {
        for (const auto& diagnostic : rejected.diagnostics()) {
            logger_->error("{}", diagnostic.to_string());
        }
        logger_->error("configuration reload rejected: {} in {}; the gateway keeps running with the previous "
                       "configuration; fix the file and reload again",
                       count_of(rejected.diagnostics().size(), "problem", "problems"), file.string());
        last_reload_rejected_ = true;
        rejection_.clear();
        next.reset();
    } catch (const std::exception& failed) {
        logger_->error("configuration reload failed: {}: {}; the gateway keeps running with the previous "
                       "configuration",
                       file.string(), failed.what());
        last_reload_rejected_ = true;
        rejection_.clear();
        next.reset();
    }
    const auto began = std::chrono::steady_clock::now();
    const auto began_cpu = thread_cpu_ms();
    if (next && prepare(*next)) {
        config_ = std::move(next);
        last_reload_rejected_ = false;
        rejection_.clear();
        apply_log_level();
        // What each component's apply() held the loop for: the loop serves every
        // Modbus TCP client, so this is the pause a reload puts between a client's
        // request and the line (docs/service.md, "Reload").
        std::string timings;
        for (auto* component : components_) {
            const auto start = std::chrono::steady_clock::now();
            try {
                component->apply(config_);
            } catch (const std::exception& failed) {
                logger_->error("{} could not apply the new configuration: {}; it may still run with parts of the "
                               "previous one; restart the service to be sure",
                               component->name(), failed.what());
            }
            timings += fmt::format("{}{} {:.2f} ms", timings.empty() ? "" : ", ", component->name(),
                                   milliseconds_since(start));
        }
        logger_->info("configuration reloaded from {} ({}); read and checked in {:.1f} ms off the loop, applied in "
                      "{:.2f} ms on the loop, {:.2f} ms of CPU ({})",
                      file.string(), describe_config(*config_), read_ms, milliseconds_since(began),
                      thread_cpu_ms() - began_cpu, timings);
    }
    ++(last_reload_rejected_ ? reloads_.rejected : reloads_.ok);
    notify("READY=1\nSTATUS=" + status_.take_if_changed(true).value_or(""));
    if (reload_again_) {
        reload_again_ = false;
        reload();
    }
}

bool Daemon::prepare(const config::Config& next) {
    std::size_t prepared = 0;
    for (; prepared < started_; ++prepared) {
        auto* component = components_[prepared];
        try {
            component->prepare(next);
        } catch (const std::exception& error) {
            for (auto i = prepared; i > 0; --i) components_[i - 1]->abandon();
            rejection_ = error.what();
            last_reload_rejected_ = true;
            logger_->error("configuration reload rejected: {} cannot apply it: {}; the gateway keeps running with "
                           "the previous configuration; fix {} and reload again",
                           component->name(), rejection_, options_.config_file.string());
            return false;
        }
    }
    return true;
}

void Daemon::request_stop(const std::string& reason) {
    if (phase_ == Phase::stopped) {
        return;
    }
    if (phase_ == Phase::stopping) {
        const auto pending = stopped_ ? stopped_->pending() : std::vector<std::string>{};
        logger_->warn("{} while stopping: exiting now{}", reason,
                      pending.empty() ? std::string() : ", without waiting for " + join(pending));
        finish();
        return;
    }
    phase_ = Phase::stopping;
    logger_->info("stopping: {}", reason);
    notify("STOPPING=1\nSTATUS=" + status_.take_if_changed(true).value_or(""));

    stopped_ = std::make_unique<CompletionBarrier>([this] {
        asio::post(io_, [this] {
            logger_->info("stopped");
            finish();
        });
    });
    for (auto i = started_; i > 0; --i) {
        auto* component = components_[i - 1];
        try {
            StopContext context(*stopped_);
            logger_->debug("stopping {}", component->name());
            component->stop(context);
        } catch (const std::exception& error) {
            logger_->error("error while stopping {}: {}", component->name(), error.what());
        }
    }
    stopped_->arm();
    if (!stopped_->complete()) {
        stop_timer_.expires_after(options_.stop_timeout);
        stop_timer_.async_wait([this](const std::error_code& error) {
            if (error || phase_ != Phase::stopping) {
                return;
            }
            logger_->warn("stop timeout ({} ms) expired: exiting without waiting for {}",
                          options_.stop_timeout.count(), join(stopped_->pending()));
            finish();
        });
    }
}

void Daemon::fail(const std::string& reason) {
    logger_->error("{}", reason);
    exit_code_ = exit_failure;
    request_stop("fatal error");
}

void Daemon::finish() {
    phase_ = Phase::stopped;
    if (watchdog_) {
        watchdog_->cancel();
    }
    status_refresh_.cancel();
    stop_timer_.cancel();
    std::error_code ignored;
    signals_.cancel(ignored);
    // Components' own pending operations are abandoned: they were told to stop
    // and had their time.
    io_.stop();
}

void Daemon::notify(const std::string& state) {
    if (logger_->should_log(spdlog::level::debug) && state != "WATCHDOG=1") {
        std::string one_line = state;
        std::replace(one_line.begin(), one_line.end(), '\n', ' ');
        logger_->debug("to the service manager: {}", one_line);
    }
    manager_.notify(state);
}

void Daemon::apply_log_level() {
    const auto level = to_spdlog_level(options_.log_level_override.value_or(config_->gateway.log_level));
    if (logger_->level() != level) {
        logger_->set_level(level);
        logger_->info("log level: {}", spdlog::level::to_string_view(level));
    }
}

void Daemon::publish_status(bool force) {
    if (phase_ == Phase::stopped) {
        return;
    }
    if (const auto status = status_.take_if_changed(force)) {
        notify("STATUS=" + *status);
    }
}

std::string Daemon::phase_note() const {
    switch (phase_) {
        case Phase::starting: {
            const auto pending = readiness_.pending();
            return pending.empty() ? "starting" : "starting, waiting for " + join(pending);
        }
        case Phase::stopping:
        case Phase::stopped:
            return "stopping";
        case Phase::running:
            break;
    }
    if (!last_reload_rejected_) return "";
    if (rejection_.empty()) return "last reload rejected (see the log)";
    // STATUS= is one line: the reason's first line, cut to what `systemctl status` shows.
    constexpr std::size_t shown = 100;
    std::string reason = rejection_.substr(0, rejection_.find('\n'));
    if (reason.size() > shown) reason = reason.substr(0, shown - 3) + "...";
    return "last reload rejected: " + reason;
}

}  // namespace fieldbridge::daemon
