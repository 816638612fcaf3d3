#include "northbound/mqtt/broker_probe.hpp"

#include <asio/connect.hpp>
#include <asio/ip/tcp.hpp>
#include <asio/steady_timer.hpp>
#include <utility>

namespace fieldbridge::northbound::mqtt {

/// One check: the resolver, the socket and the deadline share its lifetime; the
/// first outcome (connected, failed, timed out, cancelled) wins.
struct TcpBrokerProbe::Attempt : std::enable_shared_from_this<Attempt> {
    explicit Attempt(asio::io_context& io, std::function<void(bool)> callback)
        : resolver(io), socket(io), deadline(io), done(std::move(callback)) {}

    void finish(bool reachable) {
        if (!done) return;
        auto callback = std::move(done);
        done = nullptr;
        deadline.cancel();
        resolver.cancel();
        asio::error_code ignored;
        socket.close(ignored);
        if (callback) callback(reachable);
    }

    asio::ip::tcp::resolver resolver;
    asio::ip::tcp::socket socket;
    asio::steady_timer deadline;
    std::function<void(bool)> done;
};

TcpBrokerProbe::TcpBrokerProbe(asio::io_context& io, std::string host, std::uint16_t port)
    : io_(io), host_(std::move(host)), port_(port) {}

TcpBrokerProbe::~TcpBrokerProbe() { cancel(); }

void TcpBrokerProbe::probe(std::chrono::milliseconds timeout, std::function<void(bool)> done) {
    cancel();
    auto attempt = std::make_shared<Attempt>(io_, std::move(done));
    attempt_ = attempt;
    attempt->deadline.expires_after(timeout);
    attempt->deadline.async_wait([attempt](const asio::error_code& error) {
        if (!error) attempt->finish(false);
    });
    attempt->resolver.async_resolve(
        host_, std::to_string(port_),
        [attempt](const asio::error_code& error, const asio::ip::tcp::resolver::results_type& results) {
            if (error) {
                attempt->finish(false);
                return;
            }
            asio::async_connect(attempt->socket, results,
                                [attempt](const asio::error_code& connect_error, const asio::ip::tcp::endpoint&) {
                                    attempt->finish(!connect_error);
                                });
        });
}

void TcpBrokerProbe::cancel() {
    if (!attempt_) return;
    auto attempt = std::move(attempt_);
    attempt->done = nullptr;  // abandoned: nothing is reported
    attempt->deadline.cancel();
    attempt->resolver.cancel();
    asio::error_code ignored;
    attempt->socket.close(ignored);
}

}  // namespace fieldbridge::northbound::mqtt
