#include "modbus_tcp_server.hpp"

#include <array>

#include <asio/write.hpp>
#include <fmt/format.h>

#include "protocol/mbap_frame.hpp"
#include "protocol/modbus_pdu.hpp"
#include "sim_error.hpp"

namespace fieldbridge::sim::runtime {

class ModbusTcpServer::Session : public std::enable_shared_from_this<Session> {
public:
    Session(ModbusTcpServer& server, asio::ip::tcp::socket socket)
        : server_(server), socket_(std::move(socket)) {
        asio::error_code ec;
        const auto peer = socket_.remote_endpoint(ec);
        peer_ = ec ? std::string("?") : fmt::format("{}:{}", peer.address().to_string(), peer.port());
    }

    void start() {
        ++server_.open_sessions_;
        read();
    }

    void close() {
        if (closed_) {
            return;
        }
        closed_ = true;
        --server_.open_sessions_;
        asio::error_code ignored;
        socket_.shutdown(asio::ip::tcp::socket::shutdown_both, ignored);
        socket_.close(ignored);
    }

private:
    void read() {
        auto self = shared_from_this();
        socket_.async_read_some(asio::buffer(buffer_), [self](const asio::error_code& e, std::size_t n) {
            self->on_read(e, n);
        });
    }

    void on_read(const asio::error_code& error, std::size_t count) {
        if (closed_) {
            return;
        }
        if (error) {
            if (error != asio::error::eof && error != asio::error::operation_aborted) {
                server_.log_->debug("r6: client {} read error: {}", peer_, error.message());
            }
            server_.log_->debug("r6: client {} disconnected", peer_);
            close();
            return;
        }
        rx_.insert(rx_.end(), buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(count));
        while (!rx_.empty()) {
            const auto result = protocol::decode_mbap(rx_);
            if (result.need_more()) {
                break;
            }
            if (result.malformed()) {
                ++server_.counters_.malformed;
                server_.log_->warn("r6: client {} sent a malformed MBAP header ({}); closing the "
                                   "connection",
                                   peer_, protocol::to_string(result.error));
                close();
                return;
            }
            auto reply = server_.answer(result.value.transaction_id, result.value.unit_id.value,
                                        result.value.pdu);
            tx_pending_.insert(tx_pending_.end(), reply.begin(), reply.end());
            rx_.erase(rx_.begin(), rx_.begin() + static_cast<std::ptrdiff_t>(result.consumed));
        }
        write();
        read();
    }

    void write() {
        if (writing_ || tx_pending_.empty() || closed_) {
            return;
        }
        writing_ = true;
        tx_sending_.swap(tx_pending_);
        tx_pending_.clear();
        auto self = shared_from_this();
        asio::async_write(socket_, asio::buffer(tx_sending_),
                          [self](const asio::error_code& e, std::size_t) {
                              self->writing_ = false;
                              self->tx_sending_.clear();
                              if (e) {
                                  self->close();
                                  return;
                              }
                              self->write();
                          });
    }

    ModbusTcpServer& server_;
    asio::ip::tcp::socket socket_;
    std::string peer_;
    std::array<std::uint8_t, 2048> buffer_{};
    protocol::Bytes rx_;
    protocol::Bytes tx_pending_;
    protocol::Bytes tx_sending_;
    bool writing_ = false;
    bool closed_ = false;
};

ModbusTcpServer::ModbusTcpServer(asio::io_context& io, asio::ip::tcp::endpoint endpoint,
                                 std::optional<std::uint8_t> unit, Handler handler,
                                 std::shared_ptr<spdlog::logger> log)
    : io_(io),
      endpoint_(std::move(endpoint)),
      unit_(unit),
      handler_(std::move(handler)),
      log_(std::move(log)),
      acceptor_(io) {}

ModbusTcpServer::~ModbusTcpServer() { close(); }

void ModbusTcpServer::open() {
    asio::error_code ec;
    acceptor_.open(endpoint_.protocol(), ec);
    if (!ec) {
        acceptor_.set_option(asio::ip::tcp::acceptor::reuse_address(true), ec);
    }
    if (!ec) {
        acceptor_.bind(endpoint_, ec);
    }
    if (!ec) {
        acceptor_.listen(asio::socket_base::max_listen_connections, ec);
    }
    if (ec) {
        asio::error_code ignored;
        acceptor_.close(ignored);
        throw SimError(fmt::format("R6 simulator: cannot listen on {}:{}: {}; choose a free port "
                                   "with --r6 HOST:PORT",
                                   endpoint_.address().to_string(), endpoint_.port(), ec.message()));
    }
    log_->info("r6: Modbus TCP simulator listening on {}:{} ({})", endpoint_.address().to_string(),
               local_endpoint().port(),
               unit_ ? fmt::format("unit {} only", *unit_) : std::string("any unit id"));
    accept();
}

void ModbusTcpServer::close() {
    asio::error_code ignored;
    acceptor_.close(ignored);
    for (auto& weak : sessions_) {
        if (auto session = weak.lock()) {
            session->close();
        }
    }
    sessions_.clear();
}

asio::ip::tcp::endpoint ModbusTcpServer::local_endpoint() const {
    asio::error_code ec;
    auto endpoint = acceptor_.local_endpoint(ec);
    return ec ? endpoint_ : endpoint;
}

void ModbusTcpServer::accept() {
    acceptor_.async_accept([this](const asio::error_code& error, asio::ip::tcp::socket socket) {
        if (error == asio::error::operation_aborted || !acceptor_.is_open()) {
            return;
        }
        if (!error) {
            asio::error_code ignored;
            socket.set_option(asio::ip::tcp::no_delay(true), ignored);
            auto session = std::make_shared<Session>(*this, std::move(socket));
            std::erase_if(sessions_, [](const std::weak_ptr<Session>& w) { return w.expired(); });
            sessions_.push_back(session);
            ++counters_.connections;
            log_->debug("r6: client connected ({} open)", open_sessions_ + 1);
            session->start();
        } else {
            log_->warn("r6: accept failed: {}", error.message());
        }
        accept();
    });
}

protocol::Bytes ModbusTcpServer::answer(std::uint16_t transaction_id, std::uint8_t unit_id,
                                        protocol::ByteView pdu) {
    ++counters_.requests;
    protocol::Bytes reply;
    if (unit_ && unit_id != *unit_) {
        ++counters_.unit_rejected;
        reply = protocol::encode_exception(pdu.empty() ? 0 : pdu[0],
                                           protocol::ExceptionCode::gateway_target_failed);
    } else {
        try {
            reply = handler_(pdu, Clock::now());
        } catch (const std::exception& e) {
            // A model bug must not take the simulator down: answer like a device fault.
            log_->error("r6: the model failed on a request: {}", e.what());
            reply = protocol::encode_exception(pdu.empty() ? 0 : pdu[0],
                                               protocol::ExceptionCode::server_device_failure);
        }
    }
    if (reply.empty()) {
        ++counters_.unanswered;
        return {};
    }
    ++counters_.replies;
    if ((reply[0] & protocol::fc::exception_flag) != 0) {
        ++counters_.exceptions;
    }
    return protocol::encode_mbap(transaction_id, core::UnitId{unit_id}, reply);
}

nlohmann::json ModbusTcpServer::stats() const {
    return {{"listen", fmt::format("{}:{}", endpoint_.address().to_string(), local_endpoint().port())},
            {"unit", unit_ ? nlohmann::json(*unit_) : nlohmann::json("any")},
            {"connections", counters_.connections},
            {"connections_open", open_sessions_},
            {"requests", counters_.requests},
            {"replies", counters_.replies},
            {"exceptions", counters_.exceptions},
            {"unit_rejected", counters_.unit_rejected},
            {"malformed", counters_.malformed},
            {"unanswered", counters_.unanswered}};
}

}  // namespace fieldbridge::sim::runtime
