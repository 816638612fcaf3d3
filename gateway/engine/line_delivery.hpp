#pragma once
/// @file line_delivery.hpp
/// Calls what a line's scheduler collected (LineCore's deliveries), after the
/// transition: device health changes, then completions (a device's offline notice
/// before the outcomes it caused). Every shell of the line core delivers through it; its buffers are reused, so a delivery allocates
/// nothing once they have grown.
///
/// A handler may submit (the core takes it as its next event) or stop the line. A
/// delivery started from inside a handler returns at once: the one running takes
/// what the handler added, in order. An exception from a handler is logged and the
/// other handlers still run.

#include <string>
#include <vector>

#include "engine/line_log.hpp"
#include "engine/line_scheduler.hpp"

namespace fieldbridge::engine {

class LineDelivery {
public:
    /// @p line names the line in the log messages.
    LineDelivery(std::string line, LogSink log);

    /// Device online / offline (for MQTT state and alarms).
    void set_health_callback(HealthCallback callback) { on_health_ = std::move(callback); }

    /// Calls what @p scheduler collected, until it has nothing left.
    void deliver(LineScheduler& scheduler);

    /// Calls @p completion's on_done, logging what it throws.
    static void complete(LineCompletion& completion, const LogSink& log, const std::string& line);

private:
    std::string line_;
    LogSink log_;
    HealthCallback on_health_;
    std::vector<HealthChange> health_;
    std::vector<LineCompletion> completions_;
    bool delivering_ = false;
};

}  // namespace fieldbridge::engine
