#include "control_server.hpp"

#include <asio/read_until.hpp>
#include <asio/streambuf.hpp>
#include <asio/write.hpp>
#include <fmt/format.h>

#include "sim_error.hpp"

namespace fieldbridge::sim::runtime {
namespace {

/// A control line longer than this is not a command: the connection is dropped.
constexpr std::size_t max_line = 4096;

}  // namespace

class ControlServer::Connection : public std::enable_shared_from_this<Connection> {
public:
    Connection(ControlServer& server, asio::local::stream_protocol::socket socket)
        : server_(server), socket_(std::move(socket)), input_(max_line) {}

    void start() { read(); }

    void close() {
        asio::error_code ignored;
        socket_.close(ignored);
    }

private:
    void read() {
        auto self = shared_from_this();
        asio::async_read_until(socket_, input_, '\n',
                               [self](const asio::error_code& e, std::size_t n) { self->on_line(e, n); });
    }

    void on_line(const asio::error_code& error, std::size_t count) {
        if (error) {
            if (error == asio::error::not_found) {
                server_.log_->warn("control: line longer than {} bytes; closing that connection",
                                   max_line);
            }
            close();
            return;
        }
        std::string line(asio::buffers_begin(input_.data()),
                         asio::buffers_begin(input_.data()) + static_cast<std::ptrdiff_t>(count));
        input_.consume(count);
        while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) {
            line.pop_back();
        }
        std::string reply;
        try {
            reply = server_.handler_(line);
        } catch (const std::exception& e) {
            reply = fmt::format("error: {}", e.what());
        }
        // One reply line per request line.
        for (auto& c : reply) {
            if (c == '\n' || c == '\r') {
                c = ' ';
            }
        }
        reply_ = std::move(reply);
        reply_.push_back('\n');
        auto self = shared_from_this();
        asio::async_write(socket_, asio::buffer(reply_), [self](const asio::error_code& e, std::size_t) {
            if (e) {
                self->close();
                return;
            }
            self->read();
        });
    }

    ControlServer& server_;
    asio::local::stream_protocol::socket socket_;
    asio::streambuf input_;
    std::string reply_;
};

ControlServer::ControlServer(asio::io_context& io, std::filesystem::path path, Handler handler,
                             std::shared_ptr<spdlog::logger> log)
    : io_(io), path_(std::move(path)), handler_(std::move(handler)), log_(std::move(log)), acceptor_(io) {}

ControlServer::~ControlServer() { close(); }

void ControlServer::open() {
    namespace fs = std::filesystem;
    std::error_code fs_error;
    if (path_.has_parent_path()) {
        fs::create_directories(path_.parent_path(), fs_error);
    }
    const auto status = fs::symlink_status(path_, fs_error);
    if (fs::exists(status)) {
        if (!fs::is_socket(status)) {
            throw SimError(fmt::format("control socket {}: the path exists and is not a socket; "
                                       "remove it or choose another --control path",
                                       path_.string()));
        }
        fs::remove(path_, fs_error);  // stale socket of a simulator that was killed
    }
    asio::error_code ec;
    const asio::local::stream_protocol::endpoint endpoint(path_.string());
    acceptor_.open(endpoint.protocol(), ec);
    if (!ec) {
        acceptor_.bind(endpoint, ec);
    }
    if (!ec) {
        bound_ = true;
        acceptor_.listen(asio::socket_base::max_listen_connections, ec);
    }
    if (ec) {
        close();
        throw SimError(fmt::format("control socket {}: {}; check the directory is writable and "
                                   "the path is shorter than 108 bytes",
                                   path_.string(), ec.message()));
    }
    log_->info("control socket on {}", path_.string());
    accept();
}

void ControlServer::close() {
    asio::error_code ignored;
    acceptor_.close(ignored);
    for (auto& weak : connections_) {
        if (auto connection = weak.lock()) {
            connection->close();
        }
    }
    connections_.clear();
    if (bound_) {
        bound_ = false;
        std::error_code fs_error;
        std::filesystem::remove(path_, fs_error);
    }
}

void ControlServer::accept() {
    acceptor_.async_accept([this](const asio::error_code& error,
                                  asio::local::stream_protocol::socket socket) {
        if (error == asio::error::operation_aborted || !acceptor_.is_open()) {
            return;
        }
        if (!error) {
            auto connection = std::make_shared<Connection>(*this, std::move(socket));
            std::erase_if(connections_, [](const std::weak_ptr<Connection>& w) { return w.expired(); });
            connections_.push_back(connection);
            connection->start();
        } else {
            log_->warn("control: accept failed: {}", error.message());
        }
        accept();
    });
}

}  // namespace fieldbridge::sim::runtime
