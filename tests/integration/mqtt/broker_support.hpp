#pragma once
// A real mosquitto on a free 127.0.0.1 port, started and killed by the test, and an
// observer client that records what the broker delivers. Every wait is bounded.
#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <sys/types.h>

namespace fbt {

/// A free TCP port on 127.0.0.1 (bound then released).
[[nodiscard]] int free_port();
/// True once something accepts TCP connections on 127.0.0.1:@p port within @p timeout.
[[nodiscard]] bool wait_for_listener(int port, std::chrono::milliseconds timeout);

/// Spawns `mosquitto -c <conf>` and kills it (by PID) on stop() / destruction.
class Mosquitto {
public:
    explicit Mosquitto(int port);
    ~Mosquitto();
    Mosquitto(const Mosquitto&) = delete;
    Mosquitto& operator=(const Mosquitto&) = delete;

    /// Starts it and waits until it listens (throws after 5 s).
    void start();
    /// SIGTERM, then SIGKILL after 2 s; waits for the process.
    void stop();
    [[nodiscard]] int port() const noexcept { return port_; }
    [[nodiscard]] std::string uri() const { return "tcp://127.0.0.1:" + std::to_string(port_); }

private:
    int port_;
    std::string dir_;
    pid_t pid_ = -1;
};

struct Received {
    std::string topic;
    std::string payload;
    bool retained = false;
};

/// A Paho client subscribed to @p filter; records every message.
class Observer {
public:
    Observer(const std::string& uri, const std::string& filter);
    ~Observer();
    Observer(const Observer&) = delete;
    Observer& operator=(const Observer&) = delete;

    /// Publishes (QoS 1) and waits for the acknowledgement (bounded).
    void publish(const std::string& topic, const std::string& payload, bool retained = false);
    /// The first message recorded from index @p from on whose topic is @p topic and
    /// that satisfies @p match, waiting up to @p timeout.
    [[nodiscard]] std::optional<Received> wait_for(const std::string& topic,
                                                   const std::function<bool(const Received&)>& match,
                                                   std::chrono::milliseconds timeout, std::size_t from = 0);
    [[nodiscard]] std::vector<Received> messages() const;
    [[nodiscard]] std::size_t count() const;

private:
    class Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace fbt
