#include "engine/line_delivery.hpp"

#include <exception>
#include <utility>

namespace fieldbridge::engine {

LineDelivery::LineDelivery(std::string line, LogSink log) : line_(std::move(line)), log_(std::move(log)) {}

void LineDelivery::complete(LineCompletion& completion, const LogSink& log, const std::string& line) {
    if (!completion.transaction.on_done) return;
    try {
        completion.transaction.on_done(completion.outcome);
    } catch (const std::exception& error) {
        log(LogLevel::error, "line " + line + ": a completion handler threw: " + error.what());
    } catch (...) {
        log(LogLevel::error, "line " + line + ": a completion handler threw a non-standard exception");
    }
}

void LineDelivery::deliver(LineScheduler& scheduler) {
    // A handler that stops the line, or submits after a stop, adds deliveries: the
    // loop below takes them once the handler returns (the buffers are in use here).
    if (delivering_) return;
    delivering_ = true;
    while (scheduler.has_completions() || scheduler.has_health_changes()) {
        scheduler.take_health_changes(health_);
        scheduler.take_completions(completions_);
        for (const HealthChange& change : health_) {
            if (!on_health_) break;
            try {
                on_health_(change.device, change.online, change.at);
            } catch (const std::exception& error) {
                log_(LogLevel::error, "line " + line_ + ": the device health callback threw: " + error.what());
            } catch (...) {
                log_(LogLevel::error, "line " + line_ + ": the device health callback threw a non-standard exception");
            }
        }
        health_.clear();
        for (LineCompletion& completion : completions_) complete(completion, log_, line_);
        completions_.clear();
    }
    delivering_ = false;
}

}  // namespace fieldbridge::engine
