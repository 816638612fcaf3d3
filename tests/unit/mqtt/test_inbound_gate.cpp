// The bound on received messages waiting for the loop.
#include <doctest/doctest.h>

#include "northbound/mqtt/inbound_gate.hpp"

namespace fm = fieldbridge::northbound::mqtt;

TEST_CASE("inbound gate: bounded in messages and in bytes; drops are counted and reported once") {
    fm::InboundGate gate(3, 100);
    CHECK(gate.admit(40));
    CHECK(gate.admit(40));
    CHECK_FALSE(gate.admit(40));  // 120 bytes
    CHECK(gate.admit(20));
    CHECK_FALSE(gate.admit(1));   // fourth message
    CHECK(gate.dropped() == 2);
    CHECK(gate.take_unreported() == 2);
    CHECK(gate.take_unreported() == 0);
    gate.release(40);
    CHECK(gate.admit(40));
    gate.release(40);
    gate.release(40);
    gate.release(20);
    CHECK(gate.admit(100));
    CHECK_FALSE(gate.admit(1));
    CHECK(gate.admit(0));
    CHECK(gate.dropped() == 3);
}
