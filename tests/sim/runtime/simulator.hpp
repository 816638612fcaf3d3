#pragma once
/// @file simulator.hpp
/// One fieldbridge-sim process: its buses, the R6 Modbus TCP simulator, the control
/// socket, the periodic model tick and the stats file. Runs on the caller's
/// io_context (single thread); main() owns signals, --duration and READY.

#include <chrono>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <asio/io_context.hpp>
#include <asio/steady_timer.hpp>
#include <nlohmann/json.hpp>
#include <spdlog/logger.h>

#include "control_server.hpp"
#include "modbus_tcp_server.hpp"
#include "pty_bus.hpp"
#include "sim_options.hpp"

namespace fieldbridge::sim {
class R6Model;
}

namespace fieldbridge::sim::runtime {

class Simulator {
public:
    Simulator(asio::io_context& io, SimOptions options, std::shared_ptr<spdlog::logger> log);
    ~Simulator();
    Simulator(const Simulator&) = delete;
    Simulator& operator=(const Simulator&) = delete;

    /// Creates the devices, opens every pty, the R6 listener and the control socket,
    /// applies the start-up faults and starts the timers. Throws SimError.
    void start();
    /// Closes everything (links and socket files removed) and writes the final stats.
    /// Idempotent.
    void shutdown();

    /// Executes one control line; returns the one-line reply ("ok ..." / "error: ...").
    [[nodiscard]] std::string command(std::string_view line);
    [[nodiscard]] nlohmann::json stats() const;

private:
    void on_tick(const asio::error_code& error);
    void on_stats_timer(const asio::error_code& error);
    void write_stats_file() const;
    [[nodiscard]] PtyBus& bus_named(std::string_view name);
    [[nodiscard]] std::string command_device(std::string_view args);
    [[nodiscard]] std::string command_fault(std::string_view args);
    [[nodiscard]] std::string command_r6(std::string_view args);

    asio::io_context& io_;
    SimOptions options_;
    std::shared_ptr<spdlog::logger> log_;
    Clock::time_point started_;
    std::vector<std::unique_ptr<PtyBus>> buses_;
    std::unique_ptr<R6Model> r6_model_;
    std::unique_ptr<ModbusTcpServer> r6_server_;
    std::unique_ptr<ControlServer> control_;
    asio::steady_timer tick_timer_;
    asio::steady_timer stats_timer_;
    bool running_ = false;
};

}  // namespace fieldbridge::sim::runtime
