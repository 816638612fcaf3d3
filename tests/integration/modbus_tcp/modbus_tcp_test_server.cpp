// A Modbus TCP server for the integration tests: the gateway's server with in-memory
// register banks as unit targets, no serial lines. Prints "listening PORT" once it
// accepts connections and runs until SIGTERM/SIGINT.
//
//   fb_modbus_tcp_test_server [--port N] [--idle-ms N] [--max-connections N]
//
// Units: 1 and 2 are register banks (a register never written reads as its address);
// unit 2 refuses writes to registers 100-199 (access rule, exception 0x01); other
// units have no route (exception 0x0A).
#include <asio/io_context.hpp>
#include <asio/signal_set.hpp>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <iostream>
#include <memory>
#include <string_view>

#include "fake_targets.hpp"
#include "northbound/modbus_tcp/server.hpp"

int main(int argc, char** argv) {
    using namespace fieldbridge;
    using northbound::modbus_tcp::test::ImmediateTarget;
    config::ModbusTcpConfig config;
    config.listen = {config::ListenAddress{"127.0.0.1", 0}};
    for (int i = 1; i + 1 < argc; i += 2) {
        const std::string_view option = argv[i];
        const unsigned long value = std::strtoul(argv[i + 1], nullptr, 10);
        if (option == "--port") {
            config.listen.front().port = static_cast<std::uint16_t>(value);
        } else if (option == "--idle-ms") {
            config.idle_timeout = std::chrono::milliseconds{value};
        } else if (option == "--max-connections") {
            config.max_connections = value;
        } else {
            std::cerr << "unknown option " << option << "\n";
            return 2;
        }
    }
    config::AccessRule protect;
    protect.units = {core::UnitId{2}};
    protect.functions = {core::FunctionCode{0x06}, core::FunctionCode{0x10}, core::FunctionCode{0x17}};
    protect.registers = config::RegisterRange{100, 199};
    protect.action = config::RuleAction::deny;
    config.rules = {protect};

    try {
        asio::io_context io;
        engine::LogSink log;
        log.min_level = engine::LogLevel::info;
        log.write = [](engine::LogLevel level, std::string_view line) {
            std::cerr << engine::to_string(level) << ": " << line << "\n";
        };
        northbound::modbus_tcp::ModbusTcpServer server(io, std::make_shared<const config::ModbusTcpConfig>(config), log);
        ImmediateTarget unit1(io);
        ImmediateTarget unit2(io);
        server.routes().set(core::UnitId{1}, unit1);
        server.routes().set(core::UnitId{2}, unit2);
        server.start();
        asio::signal_set signals(io, SIGTERM, SIGINT);
        signals.async_wait([&](const asio::error_code&, int) {
            std::cerr << server.status() << "\n";
            server.stop();
        });
        std::printf("listening %u\n", static_cast<unsigned>(server.port()));
        std::fflush(stdout);
        io.run();
    } catch (const std::exception& e) {
        std::cerr << "fb_modbus_tcp_test_server: " << e.what() << "\n";
        return 1;
    }
    return 0;
}
