#pragma once
/// @file component.hpp
/// How the gateway's parts (line engine, Modbus TCP server, MQTT bridge) plug into
/// the daemon: each is a Component registered with Daemon::add_component() before
/// Daemon::run(). Every call below happens on the daemon's loop thread.

#include <memory>
#include <string>
#include <utility>

#include "config/config.hpp"
#include "daemon/completion_barrier.hpp"

namespace fieldbridge::daemon {

/// Takes a new, already validated configuration (SIGHUP).
class Reloadable {
public:
    Reloadable() = default;
    Reloadable(const Reloadable&) = delete;
    Reloadable& operator=(const Reloadable&) = delete;
    Reloadable(Reloadable&&) = delete;
    Reloadable& operator=(Reloadable&&) = delete;
    virtual ~Reloadable() = default;

    /// Reload, first phase, on every component before any apply(): takes what the new
    /// configuration needs and may fail to get (a new listen address), without
    /// changing what runs. Throws (saying what failed and what to do) to reject the
    /// whole reload: the daemon then calls abandon() on the components prepared so
    /// far and keeps the running configuration. Default: nothing to take.
    virtual void prepare(const config::Config& /*next*/) {}
    /// The reload was rejected after prepare(): release what it took.
    virtual void abandon() noexcept {}

    /// Switches to @p config; keeps running what did not change (spec section 7).
    /// Must not throw for a configuration the loader accepted and every component
    /// prepared: an exception is logged as an error naming the component, and the
    /// others still get it.
    virtual void apply(std::shared_ptr<const config::Config> config) = 0;
};

/// What a component gets when it starts.
class StartContext {
public:
    StartContext(std::shared_ptr<const config::Config> config, CompletionBarrier& readiness)
        : config_(std::move(config)), readiness_(readiness) {}

    [[nodiscard]] const std::shared_ptr<const config::Config>& config() const noexcept { return config_; }

    /// READY=1 waits until done() is called on the returned ticket. Take one per
    /// listener or port that must be up first (e.g. "Modbus TCP listener
    /// 0.0.0.0:502"); the name appears in STATUS= while start-up waits for it.
    [[nodiscard]] CompletionBarrier::Ticket expect_ready(std::string what) { return readiness_.expect(std::move(what)); }

private:
    std::shared_ptr<const config::Config> config_;
    CompletionBarrier& readiness_;
};

/// What a component gets when the gateway stops.
class StopContext {
public:
    explicit StopContext(CompletionBarrier& finished) : finished_(finished) {}

    /// The process exits once done() is called on every such ticket, or when the
    /// daemon's stop timeout expires (then the outstanding names are logged). Take
    /// one for work that must end cleanly: the transaction in flight on a line, the
    /// MQTT `offline` publication.
    [[nodiscard]] CompletionBarrier::Ticket expect_finished(std::string what) {
        return finished_.expect(std::move(what));
    }

private:
    CompletionBarrier& finished_;
};

class Component : public Reloadable {
public:
    /// Used in logs ("cannot start <name>: ...").
    [[nodiscard]] virtual std::string name() const = 0;

    /// Called once, in registration order, once the configuration is loaded.
    /// Opens listeners and ports; throws (with a message saying what failed and
    /// what to do) when it cannot start: the daemon then stops the components
    /// already started and exits with status 1.
    virtual void start(StartContext& context) = 0;

    /// Called once, in reverse registration order, on SIGTERM/SIGINT or after a
    /// fatal error, and only when start() returned normally.
    virtual void stop(StopContext& context) = 0;
};

}  // namespace fieldbridge::daemon
