#include "northbound/modbus_tcp/server.hpp"
#include "northbound/modbus_tcp/server_log.hpp"

#include <algorithm>
#include <asio/steady_timer.hpp>
#include <fmt/format.h>
#include <unistd.h>
#include <utility>

#include "northbound/modbus_tcp/listen_socket.hpp"
#include "northbound/modbus_tcp/modbus_tcp_error.hpp"
#include "protocol/mbap_frame.hpp"

namespace fieldbridge::northbound::modbus_tcp {
namespace {

using engine::LogLevel;
using Clock = std::chrono::steady_clock;

constexpr auto refusal_log_interval = std::chrono::seconds{10};
/// Out of file descriptors or memory: accepting again at once would spin.
constexpr auto accept_retry_delay = std::chrono::milliseconds{100};

[[nodiscard]] ServerLimits usable(ServerLimits limits) {
    limits.max_outstanding = std::clamp<std::size_t>(limits.max_outstanding, 1, 0xFFFF);
    // The buffer must hold a whole frame behind a partial one being compacted.
    limits.read_buffer_bytes = std::max(limits.read_buffer_bytes, 2 * (protocol::mbap_header_size + protocol::mbap_max_length));
    return limits;
}

/// An IPv6 listener must leave IPv4 to an IPv4 listener on the same port.
[[nodiscard]] bool shares_port_with_ipv4(const config::ModbusTcpConfig& config, const config::ListenAddress& address) {
    return std::any_of(config.listen.begin(), config.listen.end(), [&](const config::ListenAddress& other) {
        return !other.is_ipv6() && other.port == address.port;
    });
}

}  // namespace

/// Shared with its pending accept: after stop() or destruction `server` is null and
/// an accept that completes late only closes its socket.
struct ModbusTcpServer::Listener {
    Listener(ModbusTcpServer& owner, asio::ip::tcp::acceptor socket, std::string text)
        : server(&owner), acceptor(std::move(socket)), retry(acceptor.get_executor()), name(std::move(text)) {}
    ModbusTcpServer* server;
    asio::ip::tcp::acceptor acceptor;
    asio::steady_timer retry;
    std::string name;
};

ModbusTcpServer::ModbusTcpServer(asio::io_context& io, std::shared_ptr<const config::ModbusTcpConfig> config,
                                 engine::LogSink log, ServerLimits limits)
    : io_(io), context_(std::make_shared<ConnectionContext>()) {
    context_->config = std::move(config);
    context_->log = std::move(log);
    context_->limits = usable(limits);
    context_->on_closed = [this](std::uint64_t connection) { connections_.erase(connection); };
}

ModbusTcpServer::~ModbusTcpServer() {
    stop();
    context_->on_closed = nullptr;
    for (const auto& adopted : adopted_) ::close(adopted.fd);
}

std::vector<std::shared_ptr<ModbusTcpServer::Listener>> ModbusTcpServer::open_listeners(
    const config::ModbusTcpConfig& config) {
    std::vector<std::shared_ptr<Listener>> opened;
    try {
        for (const auto& address : config.listen) opened.push_back(open_listener(config, address));
    } catch (...) {
        for (auto& listener : opened) {
            listener->server = nullptr;
            asio::error_code ignored;
            listener->acceptor.close(ignored);
        }
        throw;
    }
    return opened;
}

std::shared_ptr<ModbusTcpServer::Listener> ModbusTcpServer::open_listener(const config::ModbusTcpConfig& config,
                                                                          const config::ListenAddress& address) {
    if (auto adopted = open_adopted(address)) return adopted;
    auto acceptor = open_listen_socket(io_, address, address.is_ipv6() && shares_port_with_ipv4(config, address));
    return std::make_shared<Listener>(*this, std::move(acceptor), address.to_string());
}

void ModbusTcpServer::switch_listeners(const config::ModbusTcpConfig& config) {
    // Addresses still listed keep their sockets (and their pending accept); new ones
    // come from prepare(); the others close first (a new address may need their port).
    // Connections stay whatever their listener.
    std::vector<std::shared_ptr<Listener>> kept(bound_.size());
    for (std::size_t i = 0; i < bound_.size(); ++i) {
        auto& listener = listeners_.at(i);
        if (std::find(config.listen.begin(), config.listen.end(), bound_[i]) != config.listen.end()) {
            kept[i] = listener;
            continue;
        }
        log(context_->log, LogLevel::info, "Modbus TCP: no longer listening on {}", listener->name);
        listener->server = nullptr;
        asio::error_code ignored;
        listener->acceptor.close(ignored);
        listener->retry.cancel();
    }
    std::vector<std::shared_ptr<Listener>> next;
    std::vector<config::ListenAddress> bound;
    std::vector<std::shared_ptr<Listener>> fresh;
    for (const auto& address : config.listen) {
        if (const auto old = std::find(bound_.begin(), bound_.end(), address); old != bound_.end()) {
            next.push_back(kept.at(static_cast<std::size_t>(old - bound_.begin())));
            bound.push_back(address);
            continue;
        }
        const auto ready = std::find_if(prepared_.begin(), prepared_.end(),
                                        [&address](const auto& entry) { return entry.first == address; });
        std::shared_ptr<Listener> listener = ready != prepared_.end() ? ready->second : nullptr;
        if (!listener) {
            try {
                listener = open_listener(config, address);
            } catch (const ModbusTcpError& e) {
                log(context_->log, LogLevel::error,
                    "{}; the Modbus TCP server does not listen there; fix modbus_tcp.listen and reload", e.what());
                continue;
            }
        }
        next.push_back(listener);
        bound.push_back(address);
        fresh.push_back(std::move(listener));
    }
    prepared_.clear();
    listeners_ = std::move(next);
    bound_ = std::move(bound);
    for (const auto& listener : fresh) {
        log(context_->log, LogLevel::info, "Modbus TCP: listening on {} (bound {})", listener->name,
            to_string(listener->acceptor.local_endpoint()));
        accept(listener);
    }
    for (const auto& adopted : adopted_) {
        if (std::find(bound_.begin(), bound_.end(), adopted.address) != bound_.end()) continue;
        log(context_->log, LogLevel::warning,
            "Modbus TCP: no longer accepting on {}; its socket came from systemd and stays open, so clients "
            "connecting there wait unanswered: remove it from the socket unit (ListenStream=) as well and "
            "restart fieldbridge.socket and fieldbridge.service, or list it in modbus_tcp.listen again",
            adopted.address.to_string());
    }
}

std::shared_ptr<ModbusTcpServer::Listener> ModbusTcpServer::open_adopted(const config::ListenAddress& address) {
    const auto found = std::find_if(adopted_.begin(), adopted_.end(),
                                    [&](const InheritedListener& entry) { return entry.address == address; });
    if (found == adopted_.end()) return nullptr;
    return std::make_shared<Listener>(*this, duplicate_listen_socket(io_, found->fd, address),
                                      address.to_string() + " (socket passed by systemd)");
}

void ModbusTcpServer::adopt(InheritedListener listener) { adopted_.push_back(std::move(listener)); }

void ModbusTcpServer::start() {
    if (running()) return;
    if (context_->config->listen.empty()) {
        throw ModbusTcpError("Modbus TCP: no listen address configured; add one to modbus_tcp.listen");
    }
    listeners_ = open_listeners(*context_->config);
    bound_ = context_->config->listen;
    start_accepting();
}

void ModbusTcpServer::start_accepting() {
    for (const auto& listener : listeners_) {
        log(context_->log, LogLevel::info, "Modbus TCP: listening on {} (bound {})", listener->name,
            to_string(listener->acceptor.local_endpoint()));
        accept(listener);
    }
}

void ModbusTcpServer::close_listeners() {
    for (auto& listener : listeners_) {
        listener->server = nullptr;
        asio::error_code ignored;
        listener->acceptor.close(ignored);
        listener->retry.cancel();
    }
    listeners_.clear();
}

void ModbusTcpServer::stop() {
    abandon_prepared();
    close_listeners();
    // close() removes each connection from the map: close from a copy.
    std::vector<std::shared_ptr<Connection>> open;
    open.reserve(connections_.size());
    for (auto& [id, connection] : connections_) open.push_back(connection);
    for (auto& connection : open) connection->close(CloseReason::server_stop);
    connections_.clear();
}

void ModbusTcpServer::accept(const std::shared_ptr<Listener>& listener) {
    listener->acceptor.async_accept([listener](const asio::error_code& error, asio::ip::tcp::socket socket) {
        ModbusTcpServer* server = listener->server;
        if (server == nullptr || error == asio::error::operation_aborted) return;
        if (!error) {
            server->on_accepted(std::move(socket));
            server->accept(listener);
            return;
        }
        const bool exhausted = error == asio::error::no_descriptors || error == asio::error::no_buffer_space ||
                               error == asio::error::no_memory || error.value() == ENFILE;
        log(server->context_->log, LogLevel::warning, "Modbus TCP: accept on {} failed: {}{}", listener->name,
            error.message(), exhausted ? "; retrying shortly (raise LimitNOFILE or lower max_connections)" : "");
        if (!exhausted) {
            server->accept(listener);
            return;
        }
        listener->retry.expires_after(accept_retry_delay);
        listener->retry.async_wait([listener](const asio::error_code& wait_error) {
            if (!wait_error && listener->server != nullptr) listener->server->accept(listener);
        });
    });
}

void ModbusTcpServer::on_accepted(asio::ip::tcp::socket socket) {
    asio::error_code error;
    const auto peer_endpoint = socket.remote_endpoint(error);
    if (error) return;  // reset before we got to it
    const std::string peer = to_string(peer_endpoint);
    const config::ModbusTcpConfig& config = *context_->config;
    const config::IpAddress address = to_ip_address(peer_endpoint.address());
    ServerStats& stats = context_->stats;
    if (!config.client_allowed(address)) {
        ++stats.refused_not_allowed;
        socket.close(error);
        log_refusal(fmt::format("Modbus TCP: refused {}: not in modbus_tcp.allow", peer));
        return;
    }
    if (connections_.size() >= config.max_connections) {
        ++stats.refused_max_connections;
        socket.close(error);
        log_refusal(fmt::format("Modbus TCP: refused {}: {} connections open (modbus_tcp.max_connections)", peer,
                                connections_.size()));
        return;
    }
    const auto same_client = static_cast<std::size_t>(
        std::count_if(connections_.begin(), connections_.end(),
                      [&](const auto& entry) { return entry.second->client().address == address; }));
    if (same_client >= config.max_connections_per_client) {
        ++stats.refused_per_client;
        socket.close(error);
        log_refusal(fmt::format("Modbus TCP: refused {}: {} connections open from that address "
                                "(modbus_tcp.max_connections_per_client)",
                                peer, same_client));
        return;
    }
    // Responses are small and gathered per connection: send them without Nagle's delay.
    socket.set_option(asio::ip::tcp::no_delay(true), error);
    const std::uint64_t id = next_connection_++;
    auto connection = std::make_shared<Connection>(context_, std::move(socket), ClientRef{id, address}, peer);
    connections_.emplace(id, connection);
    ++stats.connections_accepted;
    ++stats.connections_open;
    log(context_->log, LogLevel::debug, "Modbus TCP: connection {} from {} ({} open)", id, peer, connections_.size());
    connection->start();
}

void ModbusTcpServer::log_refusal(const std::string& message) {
    const auto now = Clock::now();
    if (last_refusal_log_ != Clock::time_point{} && now - last_refusal_log_ < refusal_log_interval) {
        ++refusals_not_logged_;
        return;
    }
    if (refusals_not_logged_ > 0) {
        log(context_->log, LogLevel::warning, "{} ({} more refusal(s) since the last message)", message,
            refusals_not_logged_);
    } else {
        log(context_->log, LogLevel::warning, "{}", message);
    }
    last_refusal_log_ = now;
    refusals_not_logged_ = 0;
}

void ModbusTcpServer::prepare(const config::ModbusTcpConfig& config) {
    abandon_prepared();
    if (!running() || config.listen == bound_) return;
    try {
        for (const auto& address : config.listen) {
            if (std::find(bound_.begin(), bound_.end(), address) != bound_.end()) continue;
            try {
                prepared_.emplace_back(address, open_listener(config, address));
            } catch (const ModbusTcpError&) {
                // The port may be held by one of our own listeners that this change
                // drops (0.0.0.0:502 -> 127.0.0.1:502): bind it once that one closed.
                if (!frees_port(config, address.port)) throw;
                prepared_.emplace_back(address, nullptr);
            }
        }
    } catch (...) {
        abandon_prepared();
        throw;
    }
}

bool ModbusTcpServer::frees_port(const config::ModbusTcpConfig& config, std::uint16_t port) const {
    return std::any_of(bound_.begin(), bound_.end(), [&](const config::ListenAddress& held) {
        return held.port == port && std::find(config.listen.begin(), config.listen.end(), held) == config.listen.end();
    });
}

void ModbusTcpServer::abandon_prepared() noexcept {
    for (auto& [address, listener] : prepared_) {
        if (!listener) continue;
        listener->server = nullptr;
        asio::error_code ignored;
        listener->acceptor.close(ignored);
    }
    prepared_.clear();
}

void ModbusTcpServer::apply(std::shared_ptr<const config::ModbusTcpConfig> config) {
    context_->config = std::move(config);
    const config::ModbusTcpConfig& now = *context_->config;
    if (running() && now.listen != bound_) {
        if (prepared_.empty()) {
            // Not prepared by the daemon's first phase (tests, direct use): bind now.
            try {
                prepare(now);
            } catch (const ModbusTcpError& e) {
                log(context_->log, LogLevel::error, "{}; keeping the previous listen addresses", e.what());
            }
        }
        if (!prepared_.empty() || std::all_of(now.listen.begin(), now.listen.end(), [this](const auto& address) {
                return std::find(bound_.begin(), bound_.end(), address) != bound_.end();
            })) {
            switch_listeners(now);
        }
    }
    std::vector<std::shared_ptr<Connection>> refused;
    for (auto& [id, connection] : connections_) {
        if (!now.client_allowed(connection->client().address)) refused.push_back(connection);
    }
    for (auto& connection : refused) {
        log(context_->log, LogLevel::info, "Modbus TCP: closing {}: no longer in modbus_tcp.allow", connection->peer());
        connection->close(CloseReason::not_allowed);
    }
    for (auto& [id, connection] : connections_) connection->restart_idle_timer();
}

std::vector<asio::ip::tcp::endpoint> ModbusTcpServer::local_endpoints() const {
    std::vector<asio::ip::tcp::endpoint> out;
    for (const auto& listener : listeners_) {
        asio::error_code error;
        const auto endpoint = listener->acceptor.local_endpoint(error);
        if (!error) out.push_back(endpoint);
    }
    return out;
}

std::uint16_t ModbusTcpServer::port() const {
    const auto endpoints = local_endpoints();
    return endpoints.empty() ? 0 : endpoints.front().port();
}

}  // namespace fieldbridge::northbound::modbus_tcp
