#pragma once
/// @file broker_probe.hpp
/// Whether the broker's port accepts TCP connections, without MQTT or TLS: a cheap
/// check the bridge runs while it waits out a long reconnect back-off, so that it
/// connects as soon as a broker that was down comes back (issue 15).
// Standard headers before asio's (see daemon/periodic.hpp).
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include <asio/io_context.hpp>

namespace fieldbridge::northbound::mqtt {

/// The seam (tests use a scripted one).
class BrokerProbe {
public:
    BrokerProbe() = default;
    virtual ~BrokerProbe() = default;
    BrokerProbe(const BrokerProbe&) = delete;
    BrokerProbe& operator=(const BrokerProbe&) = delete;

    /// Starts one check, replacing one in progress; @p done(reachable) runs on the loop
    /// thread within about @p timeout. Never throws.
    virtual void probe(std::chrono::milliseconds timeout, std::function<void(bool reachable)> done) = 0;
    /// Abandons the check in progress: its done is not called.
    virtual void cancel() = 0;
};

/// Resolves @p host and opens (then closes) a TCP connection to @p port.
class TcpBrokerProbe final : public BrokerProbe {
public:
    TcpBrokerProbe(asio::io_context& io, std::string host, std::uint16_t port);
    ~TcpBrokerProbe() override;

    void probe(std::chrono::milliseconds timeout, std::function<void(bool reachable)> done) override;
    void cancel() override;

private:
    struct Attempt;

    asio::io_context& io_;
    std::string host_;
    std::uint16_t port_;
    std::shared_ptr<Attempt> attempt_;
};

}  // namespace fieldbridge::northbound::mqtt
