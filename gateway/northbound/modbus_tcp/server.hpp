#pragma once
/// @file server.hpp
/// The Modbus TCP server of the gateway (spec section 4): listens on every
/// configured address, enforces the connection limit and the client allow-list at
/// accept, and runs one Connection per client (MBAP framing, access rules,
/// pipelining, idle timeout). What a unit ID leads to is the routing table's
/// business (routes()): the server itself only answers 0x01 (access denied) and
/// 0x0A (no route) locally.
///
/// Single-threaded: every call, and every target's answer, happens on the thread
/// that runs the io_context.
///
/// Usage (daemon):
///     ModbusTcpServer server(io, modbus_tcp_config, log);
///     server.routes().set(unit, target);   // before or after start()
///     server.adopt(inherited);             // optional: sockets from systemd
///     server.start();                      // throws ModbusTcpError when a bind fails
///     ... server.apply(new_config) on reload; server.stats() for STATUS= ...
///     server.stop();                       // closes listeners and clients
#include <asio/io_context.hpp>
#include <asio/ip/tcp.hpp>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "config/config.hpp"
#include "engine/line_log.hpp"
#include "northbound/modbus_tcp/connection.hpp"
#include "northbound/modbus_tcp/connection_context.hpp"
#include "northbound/modbus_tcp/listen_socket.hpp"
#include "northbound/modbus_tcp/server_stats.hpp"
#include "northbound/modbus_tcp/unit_router.hpp"

namespace fieldbridge::northbound::modbus_tcp {

class ModbusTcpServer {
public:
    ModbusTcpServer(asio::io_context& io, std::shared_ptr<const config::ModbusTcpConfig> config, engine::LogSink log,
                    ServerLimits limits = {});
    /// Stops (targets get client_closed for every open connection).
    ~ModbusTcpServer();
    ModbusTcpServer(const ModbusTcpServer&) = delete;
    ModbusTcpServer& operator=(const ModbusTcpServer&) = delete;

    /// Takes over a socket that already listens on @p listener.address (systemd socket
    /// activation): from then on that address is served from it, never bound, also
    /// after a reload that drops the address and a later one that brings it back. The
    /// server owns the socket and closes it when destroyed; while the configuration
    /// does not list its address the socket stays open but is not accepted from.
    void adopt(InheritedListener listener);

    /// Binds every configured address (or uses its adopted socket) and starts
    /// accepting. All or nothing: when one address fails, none stays open and
    /// ModbusTcpError says what to do.
    void start();
    /// Stops accepting and closes every connection. Idempotent; start() may follow.
    void stop();
    /// Reload, first phase: binds the addresses of @p config not listened on yet
    /// (held, not accepting yet). Throws ModbusTcpError, with nothing changed, when
    /// one cannot be bound: the daemon then rejects the whole reload.
    void prepare(const config::ModbusTcpConfig& config);
    /// Closes what prepare() bound (the reload was rejected). Idempotent.
    void abandon_prepared() noexcept;
    /// Reload: new access rules, allow-list, limits and idle timeout apply at once
    /// (open connections of clients no longer allowed are closed; connections
    /// beyond a lowered max_connections stay). Listen addresses still listed keep
    /// their sockets; new ones start accepting (bound by prepare(), or here when it
    /// was not called: when that fails the error is logged and the previous
    /// addresses are kept); dropped ones close. Open connections always stay.
    void apply(std::shared_ptr<const config::ModbusTcpConfig> config);

    /// Unit ID -> target. Targets must outlive their routes.
    [[nodiscard]] UnitRouter& routes() noexcept { return context_->routes; }
    [[nodiscard]] const ServerStats& stats() const noexcept { return context_->stats; }
    /// "Modbus TCP: 3 client(s), ..." for STATUS=.
    [[nodiscard]] std::string status() const { return context_->stats.summary(); }
    [[nodiscard]] bool running() const noexcept { return !listeners_.empty(); }
    /// Bound endpoints, in configuration order (the real port when the configured one is 0).
    [[nodiscard]] std::vector<asio::ip::tcp::endpoint> local_endpoints() const;
    /// The bound port of the first listener (tests configure port 0); 0 when not running.
    [[nodiscard]] std::uint16_t port() const;

private:
    struct Listener;

    [[nodiscard]] std::vector<std::shared_ptr<Listener>> open_listeners(const config::ModbusTcpConfig& config);
    /// A duplicate of the adopted socket for @p address; nullptr when none was adopted.
    [[nodiscard]] std::shared_ptr<Listener> open_adopted(const config::ListenAddress& address);
    /// The adopted socket for @p address, or a new bound one. Throws ModbusTcpError.
    [[nodiscard]] std::shared_ptr<Listener> open_listener(const config::ModbusTcpConfig& config,
                                                          const config::ListenAddress& address);
    /// True when a listener on @p port is held now and @p config drops it.
    [[nodiscard]] bool frees_port(const config::ModbusTcpConfig& config, std::uint16_t port) const;
    /// apply()'s listener change, once every new address is in prepared_ (null: to
    /// bind once the dropped listeners closed).
    void switch_listeners(const config::ModbusTcpConfig& config);
    void start_accepting();
    void close_listeners();
    void accept(const std::shared_ptr<Listener>& listener);
    void on_accepted(asio::ip::tcp::socket socket);
    /// Refusals are logged at most every few seconds, with the number left out.
    void log_refusal(const std::string& message);

    asio::io_context& io_;
    std::shared_ptr<ConnectionContext> context_;
    std::vector<std::shared_ptr<Listener>> listeners_;
    std::vector<config::ListenAddress> bound_;  ///< what listeners_ were opened for
    /// Bound by prepare() for the next apply(), not accepting yet.
    std::vector<std::pair<config::ListenAddress, std::shared_ptr<Listener>>> prepared_;
    /// Adopted sockets; listeners_ serve duplicates of them, so closing a listener
    /// (stop, reload) never closes the socket systemd passed.
    std::vector<InheritedListener> adopted_;
    std::unordered_map<std::uint64_t, std::shared_ptr<Connection>> connections_;
    std::uint64_t next_connection_ = 1;
    std::chrono::steady_clock::time_point last_refusal_log_{};
    std::uint64_t refusals_not_logged_ = 0;
};

}  // namespace fieldbridge::northbound::modbus_tcp
