#pragma once
/// @file read_load.hpp
/// A saturating read load for the line benchmarks (fb_bench_line, fb_bench_line_tcp).
#include <cstdint>

#include "engine/device_agent.hpp"
#include "engine_harness.hpp"

namespace fieldbridge::bench {

/// Keeps a fixed number of two-register input reads at @p address queued on one
/// device: each answer submits the next, so the line never runs dry. stop() lets the outstanding reads finish without
/// submitting more (in_flight() tells when they have); start() again resumes.
class ReadLoad {
public:
    ReadLoad(engine::DeviceAgent& agent, std::uint16_t address) : agent_(agent), address_(address) {}
    void start(unsigned count) {
        stopping_ = false;
        for (unsigned i = 0; i < count; ++i) submit();
    }
    void stop() { stopping_ = true; }
    [[nodiscard]] std::uint64_t completed() const noexcept { return completed_; }
    [[nodiscard]] std::uint64_t failed() const noexcept { return failed_; }
    [[nodiscard]] unsigned in_flight() const noexcept { return in_flight_; }

private:
    void submit() {
        ++in_flight_;
        agent_.request(integration::read_input(address_, 2), [this](const protocol::Response& response) {
            --in_flight_;
            if (integration::registers_of(response).size() == 2) {
                ++completed_;
            } else {
                ++failed_;
            }
            if (!stopping_) submit();
        });
    }

    engine::DeviceAgent& agent_;
    std::uint16_t address_;
    bool stopping_ = false;
    unsigned in_flight_ = 0;
    std::uint64_t completed_ = 0;
    std::uint64_t failed_ = 0;
};

}  // namespace fieldbridge::bench
