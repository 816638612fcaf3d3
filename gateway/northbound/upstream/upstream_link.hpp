#pragma once
/// @file upstream_link.hpp
/// The one managed TCP connection to an upstream Modbus TCP server (spec §5, R6
/// pass-through): connect with a timeout, reconnect with back-off (initial, doubling
/// up to max, back to initial after a connection succeeds), MBAP framing of the
/// reply stream, writes in order. It knows nothing about requests: the target pairs
/// frames with requests by transaction ID.
///
/// States, with one transition function (logged at debug, failures at warning):
///     stopped -> connecting -> up -> backoff -> connecting ...
/// A malformed MBAP header from the upstream cannot be resynchronised: the
/// connection is closed and re-established.
///
/// Loop thread only. Events are never delivered after stop() or destruction; handlers
/// still queued in the io_context keep the internals alive, so the object may be
/// destroyed with operations outstanding.
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

#include <asio/io_context.hpp>

#include "engine/line_log.hpp"
#include "engine/transaction.hpp"
#include "protocol/bytes.hpp"
#include "protocol/mbap_frame.hpp"

namespace fieldbridge::northbound::upstream {

enum class LinkState : std::uint8_t { stopped, connecting, up, backoff };
[[nodiscard]] const char* to_string(LinkState state) noexcept;

struct LinkSettings {
    std::string name;  ///< the upstream's config name, for logs
    std::string host;  ///< IP literal or host name (resolved by asio's resolver)
    std::uint16_t port = 502;
    engine::Duration connect_timeout = std::chrono::seconds{2};
    engine::Duration backoff_initial = std::chrono::milliseconds{500};
    engine::Duration backoff_max = std::chrono::seconds{30};
};

struct LinkEvents {
    std::function<void(LinkState)> state_changed;
    std::function<void(protocol::MbapFrame)> frame;
};

class UpstreamLink {
public:
    UpstreamLink(asio::io_context& io, LinkSettings settings, engine::LogSink log, LinkEvents events);
    ~UpstreamLink();
    UpstreamLink(const UpstreamLink&) = delete;
    UpstreamLink& operator=(const UpstreamLink&) = delete;

    /// Starts connecting (returns at once; failures are logged and retried).
    void start();
    /// Closes the connection and stops reconnecting. No event follows. Idempotent.
    void stop();
    /// Queues @p frame for writing; dropped unless the state is `up`.
    void send(protocol::Bytes frame);
    /// Closes the connection (reason logged) and reconnects after the back-off.
    void drop(std::string_view why);

    [[nodiscard]] LinkState state() const noexcept;
    /// Connections established so far.
    [[nodiscard]] std::uint64_t connects() const noexcept;

    struct Core;  ///< socket, timers and buffers, shared with pending handlers

private:
    std::shared_ptr<Core> core_;
};

}  // namespace fieldbridge::northbound::upstream
