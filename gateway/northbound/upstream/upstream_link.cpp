#include "northbound/upstream/upstream_link.hpp"

#include <array>
#include <deque>
#include <fmt/format.h>

#include <asio/connect.hpp>
#include <asio/ip/tcp.hpp>
#include <asio/steady_timer.hpp>
#include <asio/write.hpp>

namespace fieldbridge::northbound::upstream {

using asio::ip::tcp;

struct UpstreamLink::Core : std::enable_shared_from_this<UpstreamLink::Core> {
    Core(asio::io_context& io_, LinkSettings settings_, engine::LogSink log_, LinkEvents events_)
        : io(io_), settings(std::move(settings_)), log(std::move(log_)), events(std::move(events_)),
          socket(io_), resolver(io_), timer(io_), backoff(settings.backoff_initial) {}

    asio::io_context& io;
    LinkSettings settings;
    engine::LogSink log;
    LinkEvents events;
    tcp::socket socket;
    tcp::resolver resolver;
    asio::steady_timer timer;  ///< connect timeout, then back-off
    LinkState state = LinkState::stopped;
    engine::Duration backoff;
    std::uint64_t generation = 0;  ///< bumped on every close: stale handlers see a new value
    std::uint64_t connects = 0;
    std::array<std::uint8_t, 1024> chunk{};
    protocol::Bytes received;
    std::deque<protocol::Bytes> outgoing;
    bool writing = false;

    [[nodiscard]] std::string where() const {
        return fmt::format("upstream {} ({}:{})", settings.name, settings.host, settings.port);
    }

    /// The one transition function: every state change goes through here.
    void set_state(LinkState next, std::string_view why) {
        if (state == next) return;
        log(engine::LogLevel::debug,
            fmt::format("{}: {} -> {} ({})", where(), to_string(state), to_string(next), why));
        state = next;
        if (next == LinkState::stopped) return;  // stop() delivers no event
        if (events.state_changed) events.state_changed(next);
    }

    void close_socket() {
        ++generation;
        asio::error_code ignored;
        socket.shutdown(tcp::socket::shutdown_both, ignored);
        socket.close(ignored);
        resolver.cancel();
        timer.cancel();
        received.clear();
        outgoing.clear();
        writing = false;
    }

    void connect() {
        close_socket();
        set_state(LinkState::connecting, "connecting");
        if (state != LinkState::connecting) return;  // an event handler stopped or dropped us
        const std::uint64_t gen = generation;
        auto self = shared_from_this();
        timer.expires_after(settings.connect_timeout);
        timer.async_wait([self, gen](const asio::error_code& ec) {
            if (ec || self->generation != gen || self->state != LinkState::connecting) return;
            self->fail(fmt::format("no connection within {} ms (connect_timeout)",
                                   std::chrono::duration_cast<std::chrono::milliseconds>(
                                       self->settings.connect_timeout).count()));
        });
        asio::error_code literal_error;
        const auto address = asio::ip::make_address(settings.host, literal_error);
        if (!literal_error) {
            socket.async_connect(tcp::endpoint(address, settings.port), [self, gen](const asio::error_code& ec) {
                self->on_connected(gen, ec);
            });
            return;
        }
        // A host name: asio resolves on its internal resolver thread and completes
        // on the loop thread.
        resolver.async_resolve(settings.host, std::to_string(settings.port),
                               [self, gen](const asio::error_code& ec, const tcp::resolver::results_type& results) {
                                   if (self->generation != gen || self->state != LinkState::connecting) return;
                                   if (ec) {
                                       self->fail(fmt::format("cannot resolve '{}': {}", self->settings.host,
                                                              ec.message()));
                                       return;
                                   }
                                   asio::async_connect(self->socket, results,
                                                       [self, gen](const asio::error_code& e, const tcp::endpoint&) {
                                                           self->on_connected(gen, e);
                                                       });
                               });
    }

    void on_connected(std::uint64_t gen, const asio::error_code& ec) {
        if (generation != gen || state != LinkState::connecting) return;
        if (ec) {
            fail(ec.message());
            return;
        }
        timer.cancel();
        asio::error_code ignored;
        socket.set_option(tcp::no_delay(true), ignored);
        ++connects;
        backoff = settings.backoff_initial;
        log(engine::LogLevel::info, fmt::format("{}: connected", where()));
        read();
        set_state(LinkState::up, "connected");
    }

    /// Connection failed or lost: close, wait the back-off, connect again.
    void fail(std::string_view why) {
        if (state == LinkState::stopped) return;
        const engine::Duration wait = backoff;
        backoff = std::min(backoff * 2, settings.backoff_max);
        log(engine::LogLevel::warning,
            fmt::format("{}: {}; reconnecting in {} ms (check that the controller is on and reachable)", where(),
                        why, std::chrono::duration_cast<std::chrono::milliseconds>(wait).count()));
        close_socket();
        const std::uint64_t gen = generation;
        auto self = shared_from_this();
        timer.expires_after(wait);
        timer.async_wait([self, gen](const asio::error_code& ec) {
            if (ec || self->generation != gen || self->state != LinkState::backoff) return;
            self->connect();
        });
        set_state(LinkState::backoff, why);
    }

    void read() {
        const std::uint64_t gen = generation;
        auto self = shared_from_this();
        socket.async_read_some(asio::buffer(chunk), [self, gen](const asio::error_code& ec, std::size_t n) {
            if (self->generation != gen || self->state != LinkState::up) return;
            if (ec) {
                self->fail(ec == asio::error::eof ? std::string("the server closed the connection")
                                                  : fmt::format("read failed: {}", ec.message()));
                return;
            }
            self->received.insert(self->received.end(), self->chunk.begin(),
                                  self->chunk.begin() + static_cast<std::ptrdiff_t>(n));
            self->deliver(gen);
            if (self->generation == gen && self->state == LinkState::up) self->read();
        });
    }

    void deliver(std::uint64_t gen) {
        std::size_t offset = 0;
        while (generation == gen && state == LinkState::up) {
            const protocol::ByteView rest(received.data() + offset, received.size() - offset);
            auto result = protocol::decode_mbap(rest);
            if (result.need_more()) break;
            if (result.malformed()) {
                fail(fmt::format("malformed MBAP reply ({}); the stream cannot be resynchronised",
                                 protocol::to_string(result.error)));
                return;
            }
            offset += result.consumed;
            if (events.frame) events.frame(std::move(result.value));
        }
        if (generation == gen) {
            received.erase(received.begin(), received.begin() + static_cast<std::ptrdiff_t>(offset));
        }
    }

    void write_next() {
        if (writing || outgoing.empty() || state != LinkState::up) return;
        writing = true;
        const std::uint64_t gen = generation;
        auto self = shared_from_this();
        asio::async_write(socket, asio::buffer(outgoing.front()), [self, gen](const asio::error_code& ec, std::size_t) {
            if (self->generation != gen || self->state != LinkState::up) return;
            self->writing = false;
            if (ec) {
                self->fail(fmt::format("write failed: {}", ec.message()));
                return;
            }
            self->outgoing.pop_front();
            self->write_next();
        });
    }
};

const char* to_string(LinkState state) noexcept {
    switch (state) {
        case LinkState::stopped: return "stopped";
        case LinkState::connecting: return "connecting";
        case LinkState::up: return "up";
        case LinkState::backoff: return "backoff";
    }
    return "unknown";
}

UpstreamLink::UpstreamLink(asio::io_context& io, LinkSettings settings, engine::LogSink log, LinkEvents events)
    : core_(std::make_shared<Core>(io, std::move(settings), std::move(log), std::move(events))) {}

UpstreamLink::~UpstreamLink() { stop(); }

void UpstreamLink::start() {
    if (core_->state != LinkState::stopped) return;
    core_->backoff = core_->settings.backoff_initial;
    core_->connect();
}

void UpstreamLink::stop() {
    if (core_->state == LinkState::stopped) return;
    core_->close_socket();
    core_->set_state(LinkState::stopped, "stopped");
}

void UpstreamLink::send(protocol::Bytes frame) {
    if (core_->state != LinkState::up) return;
    core_->outgoing.push_back(std::move(frame));
    core_->write_next();
}

void UpstreamLink::drop(std::string_view why) {
    if (core_->state == LinkState::up || core_->state == LinkState::connecting) core_->fail(why);
}

LinkState UpstreamLink::state() const noexcept { return core_->state; }
std::uint64_t UpstreamLink::connects() const noexcept { return core_->connects; }

}  // namespace fieldbridge::northbound::upstream
