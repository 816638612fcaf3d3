#include "northbound/metrics/http_endpoint.hpp"

#include <arpa/inet.h>
#include <cerrno>
#include <exception>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>
#include <string_view>
#include <utility>

#include <asio/ip/tcp.hpp>
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
        daemon = mhd.start_daemon(MHD_USE_EPOLL, 0, nullptr, nullptr, &Core::on_request, this,
                                 MHD_OPTION_LISTEN_SOCKET, listen_fd,
                                 MHD_OPTION_CONNECTION_LIMIT, static_cast<unsigned int>(limits.max_connections),
                                 MHD_OPTION_CONNECTION_TIMEOUT,
                                 static_cast<unsigned int>(limits.connection_timeout.count()), MHD_OPTION_END);
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
        ready.assign(info->epoll_fd);
        watch();
        schedule();
    }

    /// Waits until MHD's epoll set has something ready.
    void watch() {
        ready.async_wait(asio::posix::stream_descriptor::wait_read,
                         [weak = weak_from_this()](const asio::error_code& error) {
                             const auto self = weak.lock();
                             if (!self || error) return;
                             self->run();
                             self->watch();
                         });
    }

    /// MHD's own deadline (idle connections); zero when it has work left over.
    void schedule() {
        MHD_UNSIGNED_LONG_LONG timeout_ms = 0;
        if (mhd.get_timeout(daemon, &timeout_ms) != MHD_YES) {
            timer.cancel();
            return;
        }
        timer.expires_after(std::chrono::milliseconds{static_cast<std::chrono::milliseconds::rep>(timeout_ms)});
        timer.async_wait([weak = weak_from_this()](const asio::error_code& error) {
            const auto self = weak.lock();
            if (!self || error) return;
            self->run();
        });
    }

    void run() {
        mhd.run(daemon);
        schedule();
    }

    static MHD_Result on_request(void* cls, MHD_Connection* connection, const char* url, const char* method,
                                 const char* /*version*/, const char* /*upload_data*/, std::size_t* /*upload_size*/,
                                 void** /*request_state*/) {
        // The try/catch wall of a C callback: nothing may unwind through MHD.
        try {
            return static_cast<Core*>(cls)->answer(connection, url, method) ? MHD_YES : MHD_NO;
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
