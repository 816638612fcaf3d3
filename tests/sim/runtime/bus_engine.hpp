#pragma once
/// @file bus_engine.hpp
/// The sans-I/O core of one simulated RS-485 bus. It receives the bytes the master
/// wrote (with the time they arrived), frames requests (RTU by predicted length,
/// WTEC ASCII from '>' to CR LF; on a mixed bus a frame starting with '>' is ASCII),
/// hands each complete frame to every device model, applies faults, and schedules
/// the replies at the moment an emulated line would deliver them. It never touches
/// a file descriptor or a clock: PtyBus feeds it and writes what it schedules.
///
/// Emulated wire (--wire-time): a byte arriving at t occupies the line from
/// max(t, line free) for one character time tc; a reply is delivered at
/// request end + 3.5·tc (the slave's end-of-frame silence) + turnaround +
/// n_reply·tc (+ any `delay` fault), all bytes at once.
/// Without wire time replies are delivered as soon as the request is complete.
/// Either way the master's silence before each request is measured against 3.5·tc
/// and a shortfall counted as a gap violation; bytes that arrive while a reply is
/// still pending collide with it and are discarded (a half-duplex device that is
/// answering does not listen).

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>
#include <spdlog/logger.h>

#include "models/bus_device.hpp"
#include "bus_stats.hpp"
#include "fault_plan.hpp"
#include "line_timing.hpp"
#include "protocol/bytes.hpp"

namespace fieldbridge::sim::runtime {

struct BusSettings {
    std::string name;                     ///< for logs, stats and fault targets
    LineTiming timing;
    bool wire_time = false;
    std::chrono::nanoseconds turnaround = std::chrono::milliseconds(1);
    std::uint64_t seed = 0;               ///< fault randomness
};

class BusEngine {
public:
    struct Output {
        Clock::time_point at;   ///< when the emulated line delivers it
        protocol::Bytes bytes;
        bool reply = false;     ///< false: an echo of the master's own bytes
    };

    BusEngine(BusSettings settings, std::vector<std::unique_ptr<BusDevice>> devices,
              std::shared_ptr<spdlog::logger> log, Clock::time_point now);

    /// Bytes read from the master side at @p now.
    void on_bytes(protocol::ByteView bytes, Clock::time_point now);
    /// When an incomplete frame is to be given up byte by byte (resynchronisation).
    [[nodiscard]] std::optional<Clock::time_point> resync_deadline() const;
    /// Silence reached: whatever cannot complete a frame is garbage.
    void on_silence(Clock::time_point now);

    [[nodiscard]] std::optional<Clock::time_point> next_output() const;
    /// Removes and returns the outputs due at @p now, in order.
    [[nodiscard]] std::vector<Output> take_due(Clock::time_point now);
    /// Records a write: @p written of the output's bytes went out at @p when.
    void on_written(const Output& output, std::size_t written, Clock::time_point when);

    /// Advances every model's motion (periodically and before each frame).
    void advance(Clock::time_point now);
    /// The port vanished (unplug): input, pending outputs and wire history are gone.
    void reset_line();
    void count_unplug() noexcept { ++wire_.unplugs; }

    /// Applies a fault spec for this bus: reply faults and echo become rules, dead and
    /// revive change device state. Throws SimError for an address with no device.
    /// unplug is the caller's (it owns the port).
    void apply_fault(const FaultSpec& spec);
    void clear_faults(std::optional<std::uint8_t> address);

    [[nodiscard]] bool has_device(std::uint8_t address) const noexcept;
    /// Forwards to the device's control(); returns its error text (empty: done).
    [[nodiscard]] std::string device_control(std::uint8_t address, std::string_view command,
                                             Clock::time_point now);

    [[nodiscard]] nlohmann::json stats(Clock::time_point now) const;
    /// The requests seen and the longest silence before one of them (the line's idle
    /// time between two frames) since the previous call; starts a new window. Lets a
    /// test measure how long a moment (a reload) left the line idle.
    [[nodiscard]] nlohmann::json take_silence_window();
    [[nodiscard]] const WireCounters& counters() const noexcept { return wire_; }
    [[nodiscard]] const BusSettings& settings() const noexcept { return settings_; }

private:
    struct Slot {
        std::unique_ptr<BusDevice> device;
        DeviceCounters counters;
        bool dead = false;
    };
    enum class Framed : std::uint8_t { more, frame, drop };
    struct Attempt {
        Framed what = Framed::more;
        std::size_t length = 0;      ///< frame: bytes of the frame; drop: bytes to drop
        std::size_t skipped = 0;     ///< frame: garbage ahead of it
        BusProtocol protocol = BusProtocol::modbus_rtu;
        std::uint8_t address = 0;
        bool crc_error = false;
    };
    enum class Discard : std::uint8_t { garbage, crc_error };

    [[nodiscard]] Attempt frame_head() const;
    void process(Clock::time_point now);
    void handle_frame(const Attempt& attempt, Clock::time_point now);
    void discard(std::size_t count, Discard why, Clock::time_point now);
    void collide(std::size_t count, Clock::time_point now);
    void schedule(Output output);
    [[nodiscard]] bool reply_pending(Clock::time_point now) const noexcept;
    void note_silence(Clock::time_point frame_start);
    [[nodiscard]] protocol::Bytes damage(protocol::Bytes reply, BusProtocol protocol,
                                         const ReplyFaults& faults, DeviceCounters& counters);
    [[nodiscard]] Slot* find(std::uint8_t address) noexcept;
    [[nodiscard]] const Slot* find(std::uint8_t address) const noexcept;

    BusSettings settings_;
    std::vector<Slot> slots_;
    std::shared_ptr<spdlog::logger> log_;
    FaultPlan faults_;
    bool has_rtu_ = false;
    bool has_ascii_ = false;
    Clock::time_point started_;

    protocol::Bytes rx_;
    std::vector<Clock::time_point> rx_end_;  ///< emulated end of each byte in rx_
    Clock::time_point last_arrival_{};
    Clock::time_point line_free_{};          ///< wire time: when the line is next idle
    std::optional<Clock::time_point> last_frame_end_;
    /// The silence window (take_silence_window()): since the last call.
    std::uint64_t window_requests_ = 0;
    std::chrono::nanoseconds window_max_silence_{};

    std::vector<Output> outputs_;            ///< ordered by `at`, stable
    std::size_t queued_replies_ = 0;
    Clock::time_point reply_busy_until_{};   ///< latest `at` of a queued reply

    WireCounters wire_;
};

}  // namespace fieldbridge::sim::runtime
