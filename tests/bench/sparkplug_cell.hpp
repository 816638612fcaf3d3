#pragma once
/// @file sparkplug_cell.hpp
/// The cell of the Sparkplug B benchmark (bench_sparkplug.cpp): 4 polled lines of 16
/// devices of 50 uint16 points (the simulator's `bench50` definition, the daemon's
/// inline points), line-e with the `generic` load shape's devices, and the changer
/// that sets every point of every polled device every second. A value says which
/// round and point it came from (point_value, round_of).
#include <atomic>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "load_shape.hpp"
#include "sim_process.hpp"

namespace fieldbridge::bench::sparkplug_cell {

inline constexpr int polled_lines = 4;
inline constexpr int devices_per_line = 16;
inline constexpr int devices = polled_lines * devices_per_line;
inline constexpr int points = 50;
inline constexpr std::chrono::milliseconds turnaround{1};  ///< the simulator's
inline constexpr std::uint8_t line_e_first_unit = 65;     ///< line-e's devices: units 65..

/// Wall-clock time, UTC ms (the payloads' timestamps are).
[[nodiscard]] std::int64_t utc_ms();
/// "line-a" .. "line-d".
[[nodiscard]] std::string polled_line(int line);
/// Device @p d (0-63) of the polled lines: "a01" .. "d16".
[[nodiscard]] std::string device_name(int d);
/// The value round @p round writes to point @p i of device @p d:
/// (round + 1000 i + 7 d) mod 65536.
[[nodiscard]] std::uint16_t point_value(std::uint64_t round, int d, int i);
/// The round (mod 65536) that wrote @p value to point @p i of device @p d.
[[nodiscard]] std::uint64_t round_of(std::uint64_t value, int d, int i);

/// The simulator's definition of a polled device (bench50.yaml).
[[nodiscard]] std::string definition_yaml();
/// The simulator's arguments: the polled lines' bench50 devices (from @p definition),
/// line-e's @p shape, wire time at @p baud, 1 ms turnaround.
[[nodiscard]] std::vector<std::string> simulator_arguments(const LoadShape& shape, std::uint32_t baud,
                                                          const std::filesystem::path& definition);
/// The daemon's configuration: Modbus TCP on @p port, the JSON bridge to @p broker_uri,
/// the edge node too when @p sparkplug (bdSeq in @p state_dir), the polled devices'
/// points every 500 ms, line-e's devices with every read to the line.
[[nodiscard]] std::string daemon_yaml(std::uint32_t baud, bool sparkplug, std::uint16_t port,
                                      const std::string& broker_uri, const std::string& state_dir,
                                      const test::SimProcess& sim, const LoadShape& shape);

/// One round of the changer: when its 64 commands were sent (UTC ms) and how many failed.
struct Round {
    std::uint64_t number = 0;
    std::int64_t start_ms = 0;
    std::int64_t end_ms = 0;
    int failed = 0;
};

/// Every second, every point of every polled device changes (one control command a
/// device), on a thread of its own until stop().
class Changer {
public:
    explicit Changer(const test::SimProcess& sim) : sim_(sim), thread_([this] { run(); }) {}
    ~Changer() { stop(); }
    Changer(const Changer&) = delete;
    Changer& operator=(const Changer&) = delete;

    void stop();
    /// While paused, no register changes (the rounds' numbers go on).
    void pause(bool paused) { paused_ = paused; }
    [[nodiscard]] std::vector<Round> rounds() const;
    [[nodiscard]] std::string first_error() const;

private:
    void run();
    /// Sleeps until @p due or stop(), whichever comes first.
    void wait_until(std::chrono::steady_clock::time_point due) const;

    const test::SimProcess& sim_;
    std::atomic<bool> stopping_{false};
    std::atomic<bool> paused_{false};
    mutable std::mutex mutex_;
    std::vector<Round> rounds_;
    std::string error_;
    std::thread thread_;  ///< last: it starts once every other member is there
};

}  // namespace fieldbridge::bench::sparkplug_cell
