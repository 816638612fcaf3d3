#pragma once
/// @file unique_fd.hpp
/// A file descriptor with one owner, closed when the owner goes: what the test
/// harnesses and benchmarks open by hand (pipes, sockets, epoll sets) without the
/// gateway's port or socket classes.
#include <unistd.h>

namespace fieldbridge::test_support {

class UniqueFd {
public:
    explicit UniqueFd(int fd = -1) noexcept : fd_(fd) {}
    ~UniqueFd() { reset(); }
    UniqueFd(UniqueFd&& other) noexcept : fd_(other.fd_) { other.fd_ = -1; }
    UniqueFd& operator=(UniqueFd&& other) noexcept {
        if (this != &other) {
            reset();
            fd_ = other.fd_;
            other.fd_ = -1;
        }
        return *this;
    }
    UniqueFd(const UniqueFd&) = delete;
    UniqueFd& operator=(const UniqueFd&) = delete;

    [[nodiscard]] int get() const noexcept { return fd_; }
    /// Closes the descriptor now (a no-op when there is none).
    void reset() noexcept {
        if (fd_ >= 0) ::close(fd_);
        fd_ = -1;
    }

private:
    int fd_;
};

}  // namespace fieldbridge::test_support
