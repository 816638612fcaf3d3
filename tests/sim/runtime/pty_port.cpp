#include "pty_port.hpp"

#include <array>
#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <fmt/format.h>
#include <pty.h>
#include <termios.h>
#include <unistd.h>

#include "sim_error.hpp"

namespace fieldbridge::sim::runtime {
namespace {

std::string errno_text(int error) { return std::strerror(error); }

void make_raw(int fd, const char* side) {
    termios tio{};
    if (::tcgetattr(fd, &tio) != 0) {
        throw SimError(fmt::format("pty {} side: tcgetattr failed: {}", side, errno_text(errno)));
    }
    ::cfmakeraw(&tio);
    tio.c_cflag |= CLOCAL | CREAD;
    tio.c_cc[VMIN] = 1;
    tio.c_cc[VTIME] = 0;
    if (::tcsetattr(fd, TCSANOW, &tio) != 0) {
        throw SimError(fmt::format("pty {} side: tcsetattr (raw mode) failed: {}", side,
                                   errno_text(errno)));
    }
}

void set_flags(int fd, bool nonblocking) {
    const int fd_flags = ::fcntl(fd, F_GETFD);
    if (fd_flags < 0 || ::fcntl(fd, F_SETFD, fd_flags | FD_CLOEXEC) != 0) {
        throw SimError(fmt::format("pty: fcntl(FD_CLOEXEC) failed: {}", errno_text(errno)));
    }
    if (nonblocking) {
        const int fl = ::fcntl(fd, F_GETFL);
        if (fl < 0 || ::fcntl(fd, F_SETFL, fl | O_NONBLOCK) != 0) {
            throw SimError(fmt::format("pty: fcntl(O_NONBLOCK) failed: {}", errno_text(errno)));
        }
    }
}

void place_link(const std::filesystem::path& link, const std::string& target) {
    namespace fs = std::filesystem;
    std::error_code ec;
    if (link.has_parent_path()) {
        fs::create_directories(link.parent_path(), ec);
        if (ec) {
            throw SimError(fmt::format("cannot create directory {} for the pty link: {}",
                                       link.parent_path().string(), ec.message()));
        }
    }
    const auto status = fs::symlink_status(link, ec);
    if (fs::exists(status)) {
        if (!fs::is_symlink(status)) {
            throw SimError(fmt::format("{} exists and is not a symlink; remove it or choose "
                                       "another bus path",
                                       link.string()));
        }
        // A link left by a simulator that was killed: replace it.
        fs::remove(link, ec);
        if (ec) {
            throw SimError(fmt::format("cannot replace the stale symlink {}: {}", link.string(),
                                       ec.message()));
        }
    }
    fs::create_symlink(target, link, ec);
    if (ec) {
        throw SimError(fmt::format("cannot create the symlink {} -> {}: {}", link.string(), target,
                                   ec.message()));
    }
}

}  // namespace

PtyPort::PtyPort(asio::io_context& io, std::filesystem::path link)
    : link_(std::move(link)), master_(io) {
    int master_fd = -1;
    int slave_fd = -1;
    if (::openpty(&master_fd, &slave_fd, nullptr, nullptr, nullptr) != 0) {
        throw SimError(fmt::format("openpty for {} failed: {}; check /dev/ptmx and the pty limit "
                                   "(/proc/sys/kernel/pty/max)",
                                   link_.string(), errno_text(errno)));
    }
    slave_fd_ = slave_fd;
    try {
        master_.assign(master_fd);
    } catch (const std::exception& e) {
        ::close(master_fd);
        ::close(slave_fd_);
        throw SimError(fmt::format("pty for {}: cannot watch the master side: {}", link_.string(),
                                   e.what()));
    }
    try {
        std::array<char, 128> name{};
        if (::ttyname_r(slave_fd_, name.data(), name.size()) != 0) {
            throw SimError(fmt::format("pty for {}: ttyname failed: {}", link_.string(),
                                       errno_text(errno)));
        }
        slave_name_ = name.data();
        set_flags(master_fd, true);
        set_flags(slave_fd_, false);
        make_raw(slave_fd_, "slave");
        make_raw(master_fd, "master");
        place_link(link_, slave_name_);
    } catch (...) {
        master_.close();
        ::close(slave_fd_);
        throw;
    }
}

PtyPort::~PtyPort() {
    std::error_code ec;
    // Remove the link only if it is still ours (another simulator may have replaced it).
    if (std::filesystem::is_symlink(std::filesystem::symlink_status(link_, ec)) &&
        std::filesystem::read_symlink(link_, ec) == slave_name_) {
        std::filesystem::remove(link_, ec);
    }
    asio::error_code ignored;
    master_.close(ignored);
    if (slave_fd_ >= 0) {
        ::close(slave_fd_);
    }
}

std::size_t PtyPort::write(protocol::ByteView bytes) {
    std::size_t done = 0;
    while (done < bytes.size()) {
        const auto n = ::write(master_.native_handle(), bytes.data() + done, bytes.size() - done);
        if (n < 0) {
            if (errno == EINTR) {
                continue;
            }
            break;  // EAGAIN: nobody drains the slave side; the caller counts the overflow
        }
        done += static_cast<std::size_t>(n);
    }
    return done;
}

}  // namespace fieldbridge::sim::runtime
