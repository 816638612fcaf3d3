#include "pty_open_watch.hpp"

#include <sys/inotify.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <fmt/format.h>

#include "sim_error.hpp"

namespace fieldbridge::sim::runtime {

namespace {

[[nodiscard]] int watch_descriptor(const std::string& slave_name) {
    const int fd = ::inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
    if (fd < 0) {
        throw SimError(fmt::format("cannot count opens of {}: inotify_init1: {}", slave_name, std::strerror(errno)));
    }
    if (::inotify_add_watch(fd, slave_name.c_str(), IN_OPEN | IN_CLOSE) < 0) {
        const int error = errno;
        ::close(fd);
        throw SimError(fmt::format("cannot count opens of {}: inotify_add_watch: {}", slave_name,
                                   std::strerror(error)));
    }
    return fd;
}

}  // namespace

PtyOpenWatch::PtyOpenWatch(asio::io_context& io, const std::string& slave_name)
    : inotify_(io, watch_descriptor(slave_name)) {
    start_read();
}

void PtyOpenWatch::start_read() {
    inotify_.async_read_some(asio::buffer(buffer_), [this](const asio::error_code& error, std::size_t count) {
        if (error) return;  // closed with the port
        // inotify(7): whole events, each a header and a name (empty for a watched file).
        std::size_t offset = 0;
        while (offset + sizeof(inotify_event) <= count) {
            inotify_event event{};
            std::memcpy(&event, buffer_.data() + offset, sizeof event);
            if ((event.mask & IN_OPEN) != 0) ++opens_;
            if ((event.mask & IN_CLOSE) != 0) ++closes_;
            offset += sizeof(inotify_event) + event.len;
        }
        start_read();
    });
}

}  // namespace fieldbridge::sim::runtime
