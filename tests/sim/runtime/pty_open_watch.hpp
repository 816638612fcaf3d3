#pragma once
/// @file pty_open_watch.hpp
/// Counts how often a program opens and closes the slave side of a simulated bus
/// (inotify IN_OPEN / IN_CLOSE on /dev/pts/N). The simulator holds the slave open
/// itself from before the watch starts, so every event counted is the gateway's: a
/// port the gateway reopened shows as one more open. Tests read the counts from
/// `stats` to prove that a reload left a line's port alone.

#include <array>
#include <cstdint>
#include <string>

#include <asio/io_context.hpp>
#include <asio/posix/stream_descriptor.hpp>

namespace fieldbridge::sim::runtime {

class PtyOpenWatch {
public:
    /// Watches @p slave_name. Throws SimError when inotify refuses.
    PtyOpenWatch(asio::io_context& io, const std::string& slave_name);
    PtyOpenWatch(const PtyOpenWatch&) = delete;
    PtyOpenWatch& operator=(const PtyOpenWatch&) = delete;
    PtyOpenWatch(PtyOpenWatch&&) = delete;
    PtyOpenWatch& operator=(PtyOpenWatch&&) = delete;
    ~PtyOpenWatch() = default;

    [[nodiscard]] std::uint64_t opens() const noexcept { return opens_; }
    [[nodiscard]] std::uint64_t closes() const noexcept { return closes_; }

private:
    void start_read();

    asio::posix::stream_descriptor inotify_;
    std::array<char, 4096> buffer_{};
    std::uint64_t opens_ = 0;
    std::uint64_t closes_ = 0;
};

}  // namespace fieldbridge::sim::runtime
