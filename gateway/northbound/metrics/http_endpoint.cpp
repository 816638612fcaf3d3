#include "northbound/metrics/http_endpoint.hpp"

#include <arpa/inet.h>
#include <cerrno>
#include <exception>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <map>
#include <optional>
#include <string_view>
#include <utility>

#include <asio/ip/tcp.hpp>
#include <asio/post.hpp>
#include <asio/posix/stream_descriptor.hpp>
#include <asio/steady_timer.hpp>
#include <fmt/format.h>
#include "northbound/metrics/exposition.hpp"
#include "northbound/metrics/microhttpd_library.hpp"
#include "northbound/modbus_tcp/listen_socket.hpp"

namespace fieldbridge::northbound::metrics {

namespace {

constexpr std::string_view metrics_path = "/metrics";

/// What the operator can do about a failed bind/listen of the metrics address.
[[nodiscard]] std::string metrics_listen_advice(const asio::error_code& error, const config::ListenAddress& address) {
    if (error == asio::error::address_in_use) {
        return fmt::format("another process listens on port {} (`ss -ltnp 'sport = :{}'` shows which); stop it or "
                           "set metrics_http.listen to a free port",
                           address.port, address.port);
    }
    if (error == asio::error::access_denied) {
        return "the system refused the bind; use a port from 1024 up for metrics_http.listen";
    }
    if (error.value() == EADDRNOTAVAIL) {
        return fmt::format("{} is not an address of this machine; set metrics_http.listen to one of its addresses",
                           address.host);
    }
    return "check metrics_http.listen";
}

/// A listening socket on @p address, released from asio: the caller owns the descriptor.
[[nodiscard]] int bind_metrics_socket(asio::io_context& io, const config::ListenAddress& address) {
    asio::error_code error;
    const auto ip = asio::ip::make_address(address.host, error);
    if (error) {
        throw MetricsHttpError(fmt::format("metrics HTTP: cannot listen on {}: {} is not an IP address",
                                           address.to_string(), address.host));
    }
    asio::ip::tcp::acceptor acceptor(io);
    const char* step = "open";
    error = modbus_tcp::bind_and_listen(acceptor, asio::ip::tcp::endpoint(ip, address.port), true, step);
    if (!error) acceptor.non_blocking(true, error);
    if (error) {
        throw MetricsHttpError(fmt::format("metrics HTTP: cannot listen on {} ({} failed: {}): {}",
                                           address.to_string(), step, error.message(),
                                           metrics_listen_advice(error, address)));
    }
    return acceptor.release();
}

[[nodiscard]] std::uint16_t bound_port(int fd) {
    sockaddr_storage local{};
    socklen_t length = sizeof local;
    if (::getsockname(fd, reinterpret_cast<sockaddr*>(&local), &length) != 0) return 0;
    if (local.ss_family == AF_INET6) return ntohs(reinterpret_cast<const sockaddr_in6*>(&local)->sin6_port);
    return ntohs(reinterpret_cast<const sockaddr_in*>(&local)->sin_port);
}

/// Queues a copy of @p body with status @p status; false when MHD refused it.
[[nodiscard]] bool respond(const MicrohttpdApi& mhd, MHD_Connection* connection, unsigned status,
                           const std::string& body, std::string_view type, bool allow_header) {
    // MHD_RESPMEM_MUST_COPY: MHD keeps its own copy, so @p body may go at once.
    MHD_Response* response = mhd.create_response_from_buffer(body.size(), const_cast<char*>(body.data()),
                                                              MHD_RESPMEM_MUST_COPY);
    if (response == nullptr) return false;
    bool ok = mhd.add_response_header(response, MHD_HTTP_HEADER_CONTENT_TYPE, std::string(type).c_str()) == MHD_YES;
    if (ok && allow_header) ok = mhd.add_response_header(response, MHD_HTTP_HEADER_ALLOW, "GET, HEAD") == MHD_YES;
    if (ok) ok = mhd.queue_response(connection, status, response) == MHD_YES;
    mhd.destroy_response(response);
    return ok;
}

}  // namespace

struct HttpEndpoint::Core : std::enable_shared_from_this<HttpEndpoint::Core> {
    Core(asio::io_context& io, config::ListenAddress listen, Render renderer, const MicrohttpdApi& library)
        : mhd(library), address(std::move(listen)), render(std::move(renderer)), ready(io), timer(io) {}

    Core(const Core&) = delete;
    Core& operator=(const Core&) = delete;

    ~Core() {
        timer.cancel();
        if (ready.is_open()) {
            // The descriptor is MHD's: asio must not close it.
            [[maybe_unused]] const int fd = ready.release();
        }
        if (daemon != nullptr) mhd.stop_daemon(daemon);  // closes the listening socket and every connection
    }

    void start(int listen_fd, const HttpEndpointLimits& limits) {
        port = bound_port(listen_fd);
        max_connections = limits.max_connections;
        header_timeout = limits.request_header_timeout;
        daemon = mhd.start_daemon(
            MHD_USE_EPOLL, 0, nullptr, nullptr, &Core::on_request, this, MHD_OPTION_LISTEN_SOCKET, listen_fd,
            MHD_OPTION_CONNECTION_LIMIT, static_cast<unsigned int>(limits.max_connections),
            MHD_OPTION_PER_IP_CONNECTION_LIMIT, static_cast<unsigned int>(limits.max_connections_per_address),
            MHD_OPTION_CONNECTION_TIMEOUT, static_cast<unsigned int>(limits.connection_timeout.count()),
            MHD_OPTION_NOTIFY_CONNECTION, &Core::on_connection, static_cast<void*>(this),
            MHD_OPTION_NOTIFY_COMPLETED, &Core::on_completed, static_cast<void*>(this), MHD_OPTION_END);
        if (daemon == nullptr) {
            ::close(listen_fd);
            throw MetricsHttpError(fmt::format("metrics HTTP: cannot serve on {}: libmicrohttpd did not start (out of "
                                               "memory or descriptors?); check LimitNOFILE and the journal",
                                               address.to_string()));
        }
        const MHD_DaemonInfo* info = mhd.get_daemon_info(daemon, MHD_DAEMON_INFO_EPOLL_FD);
        if (info == nullptr) {
            throw MetricsHttpError(fmt::format("metrics HTTP: cannot serve on {}: libmicrohttpd has no epoll "
                                               "descriptor (built without epoll support?)",
                                               address.to_string()));
        }
        epoll_fd = info->epoll_fd;
        ready.assign(epoll_fd);
        watch();
        schedule();
    }

    /// Waits until MHD's epoll set has something new ready (asio: edge-triggered).
    void watch() {
        ready.async_wait(asio::posix::stream_descriptor::wait_read,
                         [weak = weak_from_this()](const asio::error_code& error) {
                             const auto self = weak.lock();
                             if (!self || error) return;
                             self->run();
                             self->watch();
                         });
    }

    /// The next of MHD's own deadline (idle connections; zero when it has work left
    /// over) and the request-header deadlines.
    void schedule() {
        std::optional<std::chrono::steady_clock::time_point> at;
        MHD_UNSIGNED_LONG_LONG timeout_ms = 0;
        if (mhd.get_timeout(daemon, &timeout_ms) == MHD_YES) {
            at = std::chrono::steady_clock::now() +
                 std::chrono::milliseconds{static_cast<std::chrono::milliseconds::rep>(timeout_ms)};
        }
        if (const auto earliest = std::min_element(
                header_deadlines.begin(), header_deadlines.end(),
                [](const auto& a, const auto& b) { return a.second < b.second; });
            earliest != header_deadlines.end()) {
            at = at ? std::min(*at, earliest->second) : earliest->second;
        }
        if (!at) {
            timer.cancel();
            return;
        }
        timer.expires_at(*at);
        timer.async_wait([weak = weak_from_this()](const asio::error_code& error) {
            const auto self = weak.lock();
            if (!self || error) return;
            self->cut_late_headers();
            self->run();
        });
    }

    /// Ends every connection whose request header is overdue: shutdown() of its socket
    /// (MHD's, not closed here), so MHD reads the end of stream and closes it in the
    /// next run, freeing its slot.
    void cut_late_headers() {
        const auto now = std::chrono::steady_clock::now();
        for (auto it = header_deadlines.begin(); it != header_deadlines.end();) {
            if (it->second > now) {
                ++it;
                continue;
            }
            if (const MHD_ConnectionInfo* info = mhd.get_connection_info(it->first, MHD_CONNECTION_INFO_CONNECTION_FD);
                info != nullptr) {
                ::shutdown(info->connect_fd, SHUT_RDWR);
            }
            it = header_deadlines.erase(it);
        }
    }

    [[nodiscard]] unsigned connections() const {
        const MHD_DaemonInfo* info = mhd.get_daemon_info(daemon, MHD_DAEMON_INFO_CURRENT_CONNECTIONS);
        return info != nullptr ? info->num_connections : 0;
    }

    /// True while MHD's epoll set still reports something ready (a level check: the
    /// watch above would not hear of it again).
    [[nodiscard]] bool still_ready() const {
        pollfd check{epoll_fd, POLLIN, 0};
        return ::poll(&check, 1, 0) > 0 && (check.revents & POLLIN) != 0;
    }

    /// MHD_run() until it leaves nothing that only a next run would do. A run that
    /// closed connections is followed by another: MHD takes its listening socket out of
    /// its epoll set at the connection limit and puts it back only at the start of a
    /// run, so without it clients waiting in the listen backlog (and every later one)
    /// would never be accepted once the connections at the limit had gone. What is
    /// still ready afterwards runs again from the loop, after what else is waiting.
    void run() {
        for (unsigned pass = 0; pass <= max_connections; ++pass) {
            const unsigned before = connections();
            mhd.run(daemon);
            if (connections() >= before) break;
        }
        if (still_ready() && !rerun_posted) {
            rerun_posted = true;
            asio::post(timer.get_executor(), [weak = weak_from_this()] {
                const auto self = weak.lock();
                if (!self) return;
                self->rerun_posted = false;
                self->run();
            });
        }
        schedule();
    }

    /// MHD_NotifyConnectionCallback: a connection starts waiting for its first request
    /// header, or is gone.
    static void on_connection(void* cls, MHD_Connection* connection, void** /*socket_context*/,
                              MHD_ConnectionNotificationCode code) {
        auto& core = *static_cast<Core*>(cls);
        try {
            if (code == MHD_CONNECTION_NOTIFY_STARTED) {
                core.header_deadlines[connection] = std::chrono::steady_clock::now() + core.header_timeout;
            } else {
                core.header_deadlines.erase(connection);
            }
        } catch (...) {
            // Out of memory: this connection has only the idle timeout.
        }
    }

    /// MHD_RequestCompletedCallback: an answer was sent; the next request header has
    /// the same time from now.
    static void on_completed(void* cls, MHD_Connection* connection, void** /*request_state*/,
                             MHD_RequestTerminationCode /*code*/) {
        auto& core = *static_cast<Core*>(cls);
        try {
            core.header_deadlines[connection] = std::chrono::steady_clock::now() + core.header_timeout;
        } catch (...) {
            // As above.
        }
    }

    static MHD_Result on_request(void* cls, MHD_Connection* connection, const char* url, const char* method,
                                 const char* /*version*/, const char* /*upload_data*/, std::size_t* /*upload_size*/,
                                 void** /*request_state*/) {
        // The try/catch wall of a C callback: nothing may unwind through MHD.
        try {
            auto& core = *static_cast<Core*>(cls);
            core.header_deadlines.erase(connection);  // the header is complete
            return core.answer(connection, url, method) ? MHD_YES : MHD_NO;
        } catch (...) {
            return MHD_NO;
        }
    }

    [[nodiscard]] bool answer(MHD_Connection* connection, std::string_view url, std::string_view method) {
        constexpr std::string_view text = "text/plain; charset=utf-8";
        if (url != metrics_path) {
            return respond(mhd, connection, MHD_HTTP_NOT_FOUND, "not found: only /metrics is served here\n", text, false);
        }
        if (method != MHD_HTTP_METHOD_GET && method != MHD_HTTP_METHOD_HEAD) {
            return respond(mhd, connection, MHD_HTTP_METHOD_NOT_ALLOWED, "method not allowed: use GET or HEAD\n", text,
                           true);
        }
        std::string body;
        try {
            body = render();
        } catch (const std::exception& error) {
            return respond(mhd, connection, MHD_HTTP_INTERNAL_SERVER_ERROR,
                           std::string("cannot render the metrics: ") + error.what() + "\n", text, false);
        }
        return respond(mhd, connection, MHD_HTTP_OK, body, content_type, false);
    }

    const MicrohttpdApi& mhd;
    config::ListenAddress address;
    Render render;
    asio::posix::stream_descriptor ready;
    asio::steady_timer timer;
    MHD_Daemon* daemon = nullptr;
    std::uint16_t port = 0;
    int epoll_fd = -1;  ///< MHD's; watched through `ready`
    unsigned max_connections = 0;
    std::chrono::seconds header_timeout{};
    /// Connections waiting for a request header, and until when.
    std::map<MHD_Connection*, std::chrono::steady_clock::time_point> header_deadlines;
    bool rerun_posted = false;
};

HttpEndpoint::HttpEndpoint(asio::io_context& io, const config::ListenAddress& address, Render render,
                           HttpEndpointLimits limits, const std::string& library)
    : core_(std::make_shared<Core>(
          io, address, std::move(render),
          load_microhttpd(library.empty() ? std::string(microhttpd_soname) : library,
                          fmt::format("metrics HTTP: cannot serve on {}", address.to_string())))) {
    core_->start(bind_metrics_socket(io, address), limits);
}

HttpEndpoint::~HttpEndpoint() = default;

const config::ListenAddress& HttpEndpoint::address() const noexcept {
    return core_->address;
}

std::uint16_t HttpEndpoint::port() const noexcept {
    return core_->port;
}

}  // namespace fieldbridge::northbound::metrics
