#pragma once
/// @file control_server.hpp
/// The simulator's control socket: a UNIX stream socket speaking text lines. Each
/// request line gets exactly one reply line ("ok ...", or "error: ..."), so it can
/// be driven by hand (`socat - UNIX-CONNECT:/tmp/x/sim.sock`) or by a test. The
/// command language itself belongs to the Simulator (see Simulator::command).

#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <asio/io_context.hpp>
#include <asio/local/stream_protocol.hpp>
#include <spdlog/logger.h>

namespace fieldbridge::sim::runtime {

class ControlServer {
public:
    using Handler = std::function<std::string(std::string_view line)>;

    ControlServer(asio::io_context& io, std::filesystem::path path, Handler handler,
                  std::shared_ptr<spdlog::logger> log);
    ~ControlServer();
    ControlServer(const ControlServer&) = delete;
    ControlServer& operator=(const ControlServer&) = delete;

    /// Binds the socket (replacing a stale socket file) and listens. Throws SimError.
    void open();
    /// Closes the socket and every connection and removes the socket file. Idempotent.
    void close();

    class Connection;  ///< one client (defined in the .cpp)

private:
    friend class Connection;
    void accept();

    asio::io_context& io_;
    std::filesystem::path path_;
    Handler handler_;
    std::shared_ptr<spdlog::logger> log_;
    asio::local::stream_protocol::acceptor acceptor_;
    std::vector<std::weak_ptr<Connection>> connections_;
    bool bound_ = false;
};

}  // namespace fieldbridge::sim::runtime
