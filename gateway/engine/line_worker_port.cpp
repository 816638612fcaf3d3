#include "engine/line_worker_port.hpp"

#include <asio/error.hpp>
#include <stdexcept>
#include <string>

#include "core/error.hpp"

namespace fieldbridge::engine {

LinePort::LinePort(asio::io_context& io, std::unique_ptr<SerialPort> port)
    : port_(std::move(port)), descriptor_(io) {
    if (!port_) throw core::InvalidArgument("line port: no serial port given");
}

LinePort::~LinePort() { close(); }

void LinePort::open() {
    if (is_open()) return;
    port_->open();
    const int fd = port_->native_handle();
    if (fd < 0) {
        port_->close();
        throw SerialPortError("serial port " + port_->settings().path +
                              ": open gave no file descriptor to wait on (port driver bug)");
    }
    asio::error_code error;
    descriptor_.assign(fd, error);
    if (error) {
        port_->close();
        throw SerialPortError("serial port " + port_->settings().path +
                              ": cannot wait for readiness on it (" + error.message() +
                              "); the path must name a character device or a tcp:// endpoint");
    }
}

void LinePort::finish_open() {
    try {
        port_->finish_open();
    } catch (const SerialPortError&) {
        close();
        throw;
    }
}

void LinePort::close() noexcept {
    if (descriptor_.is_open()) {
        // release() aborts the waits and deregisters the fd without closing it; the
        // SerialPort owns the fd and closes it below.
        asio::error_code ignored;
        descriptor_.cancel(ignored);
        static_cast<void>(descriptor_.release());
    }
    port_->close();
    last_read_ = 0;
}

bool LinePort::is_open() const noexcept { return port_->is_open() && descriptor_.is_open(); }

std::size_t LinePort::write_some(protocol::ByteView bytes) { return port_->write_some(bytes); }

protocol::ByteView LinePort::read_some() {
    last_read_ = port_->read_some(buffer_);
    return protocol::ByteView(buffer_.data(), last_read_);
}

}  // namespace fieldbridge::engine
