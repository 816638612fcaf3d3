// A bridge in its own process, for the last-will test: connects to 127.0.0.1:<port>
// with prefix <prefix> and runs until it is killed (at most 60 s).
#include <chrono>
#include <cstdlib>
#include <iostream>

#include <asio/io_context.hpp>

#include "fake_source.hpp"
#include "northbound/mqtt/mqtt_bridge.hpp"
#include "northbound/mqtt/paho_client.hpp"

int main(int argc, char** argv) {
    if (argc != 3) {
        std::cerr << "usage: " << argv[0] << " PORT PREFIX\n";
        return 2;
    }
    namespace fm = fieldbridge::northbound::mqtt;
    asio::io_context io;
    fm::PahoOptions o;
    o.uri = std::string("tcp://127.0.0.1:") + argv[1];
    o.client_id = "fieldbridge-will-peer";
    o.will = fm::Message{std::string(argv[2]) + "/status", "offline", 1, true};
    fm::BridgeSettings s;
    s.prefix = argv[2];
    s.reconnect_initial = std::chrono::milliseconds{100};
    fm::Bridge bridge(io, s, std::make_unique<fm::PahoClient>(io, o));
    bridge.set_sources({std::make_shared<fbt::FakeSource>(io, "g1")});
    bridge.start();
    io.run_for(std::chrono::seconds{60});
    return 0;
}
