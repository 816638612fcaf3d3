// PahoClient left to the process exit (leave_to_process_exit) while a connect is still
// in flight: the CONNACK comes after the client is gone, and Paho's thread calls the
// connect's listener. That listener must still exist (under ASan, a freed one is a
// SEGV or a use-after-free report; at exit, LeakSanitizer checks that what keeps it is
// still reachable). A scripted broker on 127.0.0.1 holds the CONNACK until the client
// is destroyed.
#include <doctest/doctest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <asio/io_context.hpp>

#include "free_port.hpp"
#include "northbound/mqtt/paho_client.hpp"

namespace {

namespace fm = fieldbridge::northbound::mqtt;
using namespace std::chrono_literals;

/// Accepts one connection, reads its CONNECT and answers with a CONNACK only when told;
/// then records whether a PINGREQ follows (Paho's keep-alive: proof that the
/// connection completed on Paho's side).
class HeldBroker {
public:
    HeldBroker() {
        const fieldbridge::test::LoopbackListener listening = fieldbridge::test::listen_on_loopback();
        listener_ = listening.fd;
        port_ = listening.port;
        thread_ = std::thread([this] { serve(); });
    }
    ~HeldBroker() {
        {
            const std::lock_guard lock(mutex_);
            stop_ = true;
        }
        changed_.notify_all();
        thread_.join();
        if (peer_ >= 0) ::close(peer_);
        ::close(listener_);
    }
    HeldBroker(const HeldBroker&) = delete;
    HeldBroker& operator=(const HeldBroker&) = delete;

    [[nodiscard]] std::string uri() const { return "tcp://127.0.0.1:" + std::to_string(port_); }
    [[nodiscard]] bool wait_connect(std::chrono::milliseconds limit) { return wait([this] { return got_connect_; }, limit); }
    void answer() {
        {
            const std::lock_guard lock(mutex_);
            answer_ = true;
        }
        changed_.notify_all();
    }
    [[nodiscard]] bool wait_ping(std::chrono::milliseconds limit) { return wait([this] { return got_ping_; }, limit); }

private:
    template <typename Predicate>
    bool wait(Predicate predicate, std::chrono::milliseconds limit) {
        std::unique_lock lock(mutex_);
        return changed_.wait_for(lock, limit, predicate);
    }

    /// Reads what is there within @p limit (nothing on timeout or close).
    std::vector<std::uint8_t> read_some(int fd, std::chrono::milliseconds limit) {
        pollfd p{fd, POLLIN, 0};
        if (::poll(&p, 1, static_cast<int>(limit.count())) <= 0) return {};
        std::vector<std::uint8_t> bytes(512);
        const ssize_t n = ::read(fd, bytes.data(), bytes.size());
        bytes.resize(n > 0 ? static_cast<std::size_t>(n) : 0);
        return bytes;
    }

    bool stopping() {
        const std::lock_guard lock(mutex_);
        return stop_;
    }

    void serve() {
        pollfd p{listener_, POLLIN, 0};
        while (!stopping() && ::poll(&p, 1, 50) == 0) {
        }
        if (stopping()) return;
        peer_ = ::accept(listener_, nullptr, nullptr);
        if (peer_ < 0) return;
        // The CONNECT (packet type 1).
        while (!stopping()) {
            const auto bytes = read_some(peer_, 50ms);
            if (!bytes.empty() && (bytes[0] >> 4) == 1) break;
        }
        {
            std::unique_lock lock(mutex_);
            got_connect_ = true;
            changed_.notify_all();
            changed_.wait(lock, [this] { return answer_ || stop_; });
            if (stop_) return;
        }
        const std::uint8_t connack[] = {0x20, 0x02, 0x00, 0x00};  // accepted
        if (::write(peer_, connack, sizeof connack) != static_cast<ssize_t>(sizeof connack)) return;
        // A PINGREQ (packet type 12) once the keep-alive has passed.
        while (!stopping()) {
            const auto bytes = read_some(peer_, 50ms);
            if (!bytes.empty() && (bytes[0] >> 4) == 12) {
                const std::lock_guard lock(mutex_);
                got_ping_ = true;
                changed_.notify_all();
                return;
            }
        }
    }

    int listener_ = -1;
    int peer_ = -1;
    int port_ = 0;
    std::mutex mutex_;
    std::condition_variable changed_;
    bool got_connect_ = false;
    bool answer_ = false;
    bool got_ping_ = false;
    bool stop_ = false;
    std::thread thread_;
};

/// A client named @p name whose CONNECT @p broker has read (and holds the answer to);
/// each connected / connect_failed event counts in @p events.
std::unique_ptr<fm::PahoClient> connecting_client(asio::io_context& io, HeldBroker& broker, const std::string& name,
                                                  std::atomic<int>& events) {
    fm::PahoOptions o;
    o.uri = broker.uri();
    o.client_id = "fieldbridge-test-" + name;
    o.keep_alive = 1s;
    o.will = fm::Message{name + "-test/status", "offline", 1, true};
    auto client = std::make_unique<fm::PahoClient>(io, o);
    fm::ClientEvents e;
    e.connected = [&events] { ++events; };
    e.connect_failed = [&events](const std::string&) { ++events; };
    client->set_events(std::move(e));
    client->connect();
    REQUIRE(broker.wait_connect(5s));
    return client;
}

}  // namespace

TEST_CASE("paho client: left to the process exit with a connect in flight, the late CONNACK reaches a live listener") {
    HeldBroker broker;
    asio::io_context io;
    std::atomic<int> events{0};
    auto client = connecting_client(io, broker, "exit", events);

    client->leave_to_process_exit();
    client.reset();
    broker.answer();
    // Paho's thread took the CONNACK (and called the connect's listener) before its
    // keep-alive sends a PINGREQ.
    CHECK(broker.wait_ping(10s));
    // Nothing reaches the loop from a client that is gone.
    io.run_for(100ms);
    CHECK(events == 0);
}

TEST_CASE("paho client: destroyed with a connect in flight, the late CONNACK reaches nothing") {
    HeldBroker broker;
    asio::io_context io;
    std::atomic<int> events{0};
    auto client = connecting_client(io, broker, "destroyed", events);
    client.reset();
    broker.answer();
    CHECK_FALSE(broker.wait_ping(2s));
    io.run_for(100ms);
    CHECK(events == 0);
}
