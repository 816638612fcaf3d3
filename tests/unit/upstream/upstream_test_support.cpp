#include "upstream_test_support.hpp"

#include <array>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <fmt/format.h>
#include <poll.h>
#include <spawn.h>
#include <stdexcept>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

#include <asio/write.hpp>

#include "protocol/mbap_frame.hpp"
#include "temp_dir.hpp"

extern char** environ;

namespace fbtest {
namespace {

using Clock = std::chrono::steady_clock;

/// Reads one line from @p fd before @p deadline; false on timeout or EOF.
bool read_line(int fd, std::string& line, Clock::time_point deadline) {
    line.clear();
    for (;;) {
        const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
        if (left <= 0) return false;
        pollfd p{fd, POLLIN, 0};
        if (::poll(&p, 1, static_cast<int>(left)) <= 0) continue;
        char c = 0;
        const ssize_t n = ::read(fd, &c, 1);
        if (n <= 0) return false;
        if (c == '\n') return true;
        line.push_back(c);
    }
}

}  // namespace

std::uint16_t free_port() {
    asio::io_context io;
    asio::ip::tcp::acceptor a(io, asio::ip::tcp::endpoint(asio::ip::make_address("127.0.0.1"), 0));
    return a.local_endpoint().port();
}

bool run_until(asio::io_context& io, const std::function<bool()>& done, std::chrono::milliseconds timeout) {
    const auto deadline = Clock::now() + timeout;
    while (!done()) {
        if (Clock::now() >= deadline) return false;
        io.restart();
        io.run_for(std::chrono::milliseconds{5});
    }
    return true;
}

void run_for(asio::io_context& io, std::chrono::milliseconds duration) {
    const auto deadline = Clock::now() + duration;
    while (Clock::now() < deadline) {
        io.restart();
        io.run_for(std::chrono::milliseconds{5});
    }
}

fieldbridge::config::UpstreamConfig config_for(std::uint16_t port) {
    using std::chrono::milliseconds;
    fieldbridge::config::UpstreamConfig c;
    c.name = "r6";
    c.host = "127.0.0.1";
    c.port = port;
    c.connect_timeout = milliseconds{500};
    c.response_timeout = milliseconds{500};
    c.reconnect_backoff = {milliseconds{20}, milliseconds{200}};
    c.poll_period = milliseconds{100};
    c.command_ttl = milliseconds{2000};
    c.queue_limit = 64;
    c.units = {{10, 1, "robot"}};
    return c;
}

fieldbridge::engine::LogSink CapturedLog::sink(fieldbridge::engine::LogLevel min) const {
    auto store = lines;
    return {[store](fieldbridge::engine::LogLevel level, std::string_view text) {
                store->push_back(fmt::format("[{}] {}", fieldbridge::engine::to_string(level), text));
            },
            min};
}

bool CapturedLog::contains(const std::string& text) const {
    for (const auto& l : *lines) {
        if (l.find(text) != std::string::npos) return true;
    }
    return false;
}

fieldbridge::northbound::PduHandler capture(std::shared_ptr<Answer> answer) {
    return [answer](Bytes pdu) {
        answer->done = true;
        answer->pdu = std::move(pdu);
        ++answer->calls;
    };
}

Bytes hex(const std::string& text) {
    Bytes out;
    std::size_t i = 0;
    while (i < text.size()) {
        if (text[i] == ' ') {
            ++i;
            continue;
        }
        out.push_back(static_cast<std::uint8_t>(std::stoul(text.substr(i, 2), nullptr, 16)));
        i += 2;
    }
    return out;
}

std::string to_hex(const Bytes& bytes) {
    std::string out;
    for (const auto b : bytes) out += fmt::format("{}{:02x}", out.empty() ? "" : " ", b);
    return out;
}

// ---- SimProcess ---------------------------------------------------------------

SimProcess::SimProcess(std::uint16_t port) : port_(port) {
    dir_ = fieldbridge::test::make_temp_dir("fb-upstream").string();
    start();
}

SimProcess::~SimProcess() {
    kill();
    ::unlink((dir_ + "/sim.sock").c_str());
    ::rmdir(dir_.c_str());
}

void SimProcess::start() {
    if (pid_ > 0) return;
    int out[2];
    if (::pipe(out) != 0) throw std::runtime_error("pipe failed");
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, out[1], STDOUT_FILENO);
    posix_spawn_file_actions_addclose(&actions, out[0]);
    posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, (dir_ + "/sim.log").c_str(),
                                     O_WRONLY | O_CREAT | O_APPEND, 0644);
    const std::string endpoint = fmt::format("127.0.0.1:{}", port_);
    const std::string control = dir_ + "/sim.sock";
    std::vector<std::string> args{FB_SIM_BINARY, "--r6", endpoint, "--control", control};
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    const int rc = ::posix_spawn(&pid_, FB_SIM_BINARY, &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    ::close(out[1]);
    if (rc != 0) {
        ::close(out[0]);
        pid_ = -1;
        throw std::runtime_error(fmt::format("cannot start {}: {}", FB_SIM_BINARY, std::strerror(rc)));
    }
    // Sanitizer builds start slowly on a busy machine.
    const auto deadline = Clock::now() + std::chrono::seconds{20};
    std::string line;
    bool ready = false;
    while (read_line(out[0], line, deadline)) {
        if (line == "READY") {
            ready = true;
            break;
        }
    }
    ::close(out[0]);  // the simulator prints nothing else on stdout we need
    if (!ready) {
        kill();
        throw std::runtime_error(fmt::format("fieldbridge-sim did not print READY within 20 s (log: {}/sim.log)", dir_));
    }
}

void SimProcess::kill() {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGTERM);
    const auto deadline = Clock::now() + std::chrono::seconds{5};
    int status = 0;
    while (::waitpid(pid_, &status, WNOHANG) == 0) {
        if (Clock::now() >= deadline) {
            ::kill(pid_, SIGKILL);
            ::waitpid(pid_, &status, 0);
            break;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds{5});  // test thread, not a loop
    }
    pid_ = -1;
}

std::string SimProcess::control(const std::string& line) {
    const int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
    if (fd < 0) throw std::runtime_error("socket failed");
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    const std::string path = dir_ + "/sim.sock";
    std::snprintf(addr.sun_path, sizeof addr.sun_path, "%s", path.c_str());
    if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
        ::close(fd);
        throw std::runtime_error("cannot connect to the simulator's control socket " + path);
    }
    const std::string request = line + "\n";
    if (::write(fd, request.data(), request.size()) != static_cast<ssize_t>(request.size())) {
        ::close(fd);
        throw std::runtime_error("control write failed");
    }
    std::string reply;
    const bool ok = read_line(fd, reply, Clock::now() + std::chrono::seconds{5});
    ::close(fd);
    if (!ok) throw std::runtime_error("no control reply to '" + line + "' within 5 s");
    return reply;
}

// ---- FakeUpstream -------------------------------------------------------------

FakeUpstream::FakeUpstream(asio::io_context& io, OnRequest on_request)
    : acceptor_(io, asio::ip::tcp::endpoint(asio::ip::make_address("127.0.0.1"), 0)),
      chunk_(std::make_shared<std::array<std::uint8_t, 1024>>()), on_request_(std::move(on_request)) {
    accept();
}

FakeUpstream::~FakeUpstream() {
    *alive_ = false;
    asio::error_code ignored;
    acceptor_.close(ignored);
    if (socket_) socket_->close(ignored);
}

std::uint16_t FakeUpstream::port() const { return acceptor_.local_endpoint().port(); }

void FakeUpstream::accept() {
    auto alive = alive_;
    acceptor_.async_accept([this, alive](const asio::error_code& ec, asio::ip::tcp::socket socket) {
        if (ec || !*alive) return;
        ++connections_;
        socket_ = std::make_shared<asio::ip::tcp::socket>(std::move(socket));
        received_.clear();
        read();
        accept();
    });
}

void FakeUpstream::read() {
    auto alive = alive_;
    auto socket = socket_;
    auto chunk = chunk_;
    socket->async_read_some(asio::buffer(*chunk), [this, alive, socket, chunk](const asio::error_code& ec, std::size_t n) {
        if (ec || !*alive || socket != socket_) return;
        received_.insert(received_.end(), chunk->begin(), chunk->begin() + static_cast<std::ptrdiff_t>(n));
        for (;;) {
            auto frame = fieldbridge::protocol::decode_mbap(received_);
            if (!frame.complete()) break;
            received_.erase(received_.begin(), received_.begin() + static_cast<std::ptrdiff_t>(frame.consumed));
            Request r{frame.value.transaction_id, frame.value.unit_id, frame.value.pdu};
            requests_.push_back(r);
            on_request_(*this, r);
            if (!*alive) return;
        }
        read();
    });
}

void FakeUpstream::send(std::uint16_t transaction_id, std::uint8_t unit, const Bytes& pdu) {
    if (!socket_) return;
    auto frame = std::make_shared<Bytes>(fieldbridge::protocol::encode_mbap(transaction_id, unit, pdu));
    asio::async_write(*socket_, asio::buffer(*frame), [frame](const asio::error_code&, std::size_t) {});
}

}  // namespace fbtest
