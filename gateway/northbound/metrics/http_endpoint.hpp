#pragma once
/// @file http_endpoint.hpp
/// `GET /metrics` over HTTP: libmicrohttpd (docs/dependencies.md) driven from the
/// daemon's asio loop, without a thread of its own. MHD runs in epoll mode; its
/// epoll descriptor is watched by the loop for readiness, MHD_run() handles what is
/// ready, and a timer set from MHD_get_timeout() and the request-header deadlines
/// closes idle and trickling connections. A scrape renders on the loop thread (a
/// quick walk over in-memory counters), so it never races the lines, and the
/// response is copied to MHD at once.
///
/// asio watches a descriptor edge-triggered: it hears of MHD's epoll set only when
/// something new becomes ready in it. So a run never leaves work behind that no new
/// event would announce (http_endpoint.cpp, Core::run()): MHD puts its listening
/// socket back into its set only at the start of a run after a connection below the
/// limit was closed, and what is still ready after a run is run again at once.
///
/// libmicrohttpd is loaded with dlopen() by the first endpoint (microhttpd_library.hpp),
/// so a daemon without `metrics_http` maps neither it nor GnuTLS.
///
/// Only GET and HEAD on /metrics: 404 for another path, 405 (with `Allow`) for
/// another method. Connections are bounded in number, in number per client address,
/// in idle time and in the time to send a request's header (a client trickling bytes
/// is not idle but is cut all the same).
// Standard headers before asio's (see daemon/daemon.hpp).
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>

#include <asio/io_context.hpp>

#include "config/config.hpp"
#include "core/error.hpp"

namespace fieldbridge::northbound::metrics {

/// Start-up failures of the endpoint; the message says which address, what failed
/// and what to do.
class MetricsHttpError : public core::Error {
public:
    using core::Error::Error;
};

struct HttpEndpointLimits {
    /// Prometheus scrapes with one connection; a few more for curl and a second server.
    unsigned max_connections = 8;
    /// Connections from one client address; beyond, MHD closes a new one at once, so
    /// one host cannot take every slot.
    unsigned max_connections_per_address = 4;
    /// An idle connection is closed after this.
    std::chrono::seconds connection_timeout{10};
    /// A connection must have sent a whole request header this long after it was
    /// accepted or its previous answer was sent; otherwise it is closed, however
    /// slowly it keeps sending.
    std::chrono::seconds request_header_timeout{5};
};

class HttpEndpoint {
public:
    /// The body of a 200 answer (Prometheus text). Called on the loop thread; an
    /// exception becomes a 500 answer whose body is its message.
    using Render = std::function<std::string()>;

    /// Binds and listens on @p address (port 0: a free port, see port()) and starts
    /// serving on @p io. @p library: the libmicrohttpd to load (empty: its SONAME; a
    /// seam for tests). Throws MetricsHttpError when the library cannot be loaded or
    /// the address cannot be used.
    HttpEndpoint(asio::io_context& io, const config::ListenAddress& address, Render render,
                 HttpEndpointLimits limits = {}, const std::string& library = {});
    /// Closes the listener and every connection.
    ~HttpEndpoint();
    HttpEndpoint(const HttpEndpoint&) = delete;
    HttpEndpoint& operator=(const HttpEndpoint&) = delete;

    /// The address as configured.
    [[nodiscard]] const config::ListenAddress& address() const noexcept;
    /// The port actually bound (differs from address().port when that is 0).
    [[nodiscard]] std::uint16_t port() const noexcept;

    struct Core;  ///< MHD, the watched descriptor and the timer; shared with pending handlers

private:
    std::shared_ptr<Core> core_;
};

}  // namespace fieldbridge::northbound::metrics
