#pragma once
// Driving an asio loop from a test until something happens, bounded: the MQTT tests
// over the real engine / upstream wait for what the broker delivers this way.
#include <chrono>
#include <functional>
#include <optional>
#include <string>

#include <asio/io_context.hpp>
#include <nlohmann/json.hpp>

#include "broker_support.hpp"

namespace fbt {

/// Runs @p io in 10 ms slices until @p done or @p limit; false on the limit.
inline bool run_until(asio::io_context& io, const std::function<bool()>& done,
                      std::chrono::milliseconds limit = std::chrono::seconds{15}) {
    const auto until = std::chrono::steady_clock::now() + limit;
    while (!done()) {
        if (std::chrono::steady_clock::now() > until) return false;
        io.restart();
        io.run_for(std::chrono::milliseconds{10});
    }
    return true;
}

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
