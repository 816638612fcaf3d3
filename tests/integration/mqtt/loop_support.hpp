#pragma once
// What the MQTT tests over the real engine / upstream wait for: a JSON message the
// broker delivers (run_until.hpp drives the loop).
#include <chrono>
#include <functional>
#include <optional>
#include <string>

#include <asio/io_context.hpp>
#include <nlohmann/json.hpp>

#include "broker_support.hpp"
#include "run_until.hpp"

namespace fbt {

using fieldbridge::test_support::run_until;

/// Runs @p io until @p observer has a JSON message on @p topic (from index @p from)
/// that @p match accepts; nullopt when none came within run_until's limit.
inline std::optional<nlohmann::json> expect(asio::io_context& io, Observer& observer, const std::string& topic,
                                            const std::function<bool(const nlohmann::json&)>& match,
                                            std::size_t from = 0) {
    std::optional<Received> found;
    run_until(io, [&] {
        found = observer.wait_for(topic, [&](const Received& r) {
            const auto j = nlohmann::json::parse(r.payload, nullptr, false);
            return !j.is_discarded() && match(j);
        }, std::chrono::milliseconds{0}, from);
        return found.has_value();
    });
    if (!found) return std::nullopt;
    return nlohmann::json::parse(found->payload);
}

}  // namespace fbt
