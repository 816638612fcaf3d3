#pragma once
/// @file pty_port.hpp
/// One pseudo-terminal pair standing in for a serial line: the master side is the
/// simulated bus, the slave side is what the gateway opens, through a symlink at a
/// stable path (e.g. /tmp/fieldbridge-demo/line-a -> /dev/pts/7). RAII: closing the
/// port closes both sides and removes the symlink, so the gateway sees the port
/// vanish exactly as when a USB adapter is unplugged.

#include <filesystem>
#include <string>

#include <asio/io_context.hpp>
#include <asio/posix/stream_descriptor.hpp>

#include "protocol/bytes.hpp"

namespace fieldbridge::sim::runtime {

class PtyPort {
public:
    /// Opens a pty pair in raw mode and links @p link to its slave, creating the
    /// directory and replacing a stale symlink. Throws SimError.
    PtyPort(asio::io_context& io, std::filesystem::path link);
    ~PtyPort();
    PtyPort(const PtyPort&) = delete;
    PtyPort& operator=(const PtyPort&) = delete;
    PtyPort(PtyPort&&) = delete;
    PtyPort& operator=(PtyPort&&) = delete;

    /// The master side, for asynchronous reads.
    [[nodiscard]] asio::posix::stream_descriptor& master() noexcept { return master_; }
    /// Writes what the pty accepts now, without blocking; returns the count.
    [[nodiscard]] std::size_t write(protocol::ByteView bytes);

    [[nodiscard]] const std::string& slave_name() const noexcept { return slave_name_; }
    [[nodiscard]] const std::filesystem::path& link() const noexcept { return link_; }

private:
    std::filesystem::path link_;
    std::string slave_name_;
    /// The simulator keeps the slave open itself: otherwise the master reads EIO
    /// whenever the gateway has the port closed (between reconnects).
    int slave_fd_ = -1;
    asio::posix::stream_descriptor master_;
};

}  // namespace fieldbridge::sim::runtime
