// Every example frame of tests/vectors/vectors.yaml for the serial devices, replayed
// against a fresh model brought into the state the manual's example assumes. A vector
// without an entry here fails the test, so a new example cannot be forgotten.
#include <doctest/doctest.h>

#include <functional>
#include <memory>
#include <string_view>

#include "models/excd_model.hpp"
#include "models/wtec_ascii_model.hpp"
#include "models/wtec_rtu_model.hpp"
#include "models/xeg_model.hpp"
#include "protocol/wtec_ascii_commands.hpp"
#include "sim_test_support.hpp"
#include "vectors.hpp"

namespace fieldbridge::test {
namespace {

namespace wtec = protocol::wtec;

enum class Expect : std::uint8_t {
    exact,         ///< the reply is the vector's response, byte for byte
    no_reply,      ///< broadcast, or a request whose CRC does not verify
    acknowledged,  ///< the manual shows no reply; the model answers normally (not an exception)
    corrected_d,   ///< the printed request is malformed; the 8-digit D gets the printed reply
};

using Setup = std::function<void(sim::BusDevice&, SimClock&)>;

struct Case {
    std::string_view what;
    Setup setup;
    Expect expect = Expect::exact;
};

void send(sim::BusDevice& device, SimClock& clock, const protocol::Bytes& frame) {
    (void)device.on_frame(frame, clock.now());
}

Setup nothing() {
    return [](sim::BusDevice&, SimClock&) {};
}

Setup xeg_reset_and_wait() {
    return [](sim::BusDevice& d, SimClock& c) {
        send(d, c, rtu("02 10 06 10 00 01 02 00 01"));
        c.advance_s(30);
    };
}

Setup wtec_rtu_initialized() {
    return [](sim::BusDevice& d, SimClock& c) {
        send(d, c, rtu("01 06 01 00 00 01"));
        c.advance_s(1);
    };
}

Setup wtec_ascii_homed() {
    return [](sim::BusDevice& d, SimClock& c) {
        send(d, c, ascii(">01G6158"));
        c.advance_s(1);
    };
}

const std::vector<Case>& cases() {
    static const std::vector<Case> all = {
        // hiwin-xeg (ID 2)
        {"write gripper model XEG-32 (0x0A20) to 0x0600, id 2", nothing()},
        {"read gripper model 0x0600", nothing()},
        {"read firmware 0x0303-0x0306 -> V3.0.1.884", nothing()},
        {"write reset 0x0610=1", nothing()},
        {"read status 0x0301 -> 1 working",
         [](sim::BusDevice& d, SimClock& c) { send(d, c, rtu("02 10 06 10 00 01 02 00 01")); }},
        {"read status 0x0301 -> 0 idle", xeg_reset_and_wait()},
        {"write Expert 0x0640-0x0646: dir 0, move 10.00mm, 80.00mm/s, hold 5.00mm, 20.00mm/s, 100%, flag 1",
         xeg_reset_and_wait()},
        {"broadcast Move 0x0630-0x0632: 32.00mm, 80.00mm/s, flag 1 (no reply)", xeg_reset_and_wait(),
         Expect::no_reply},
        {"read status 0x0301 -> 2 positioned",
         [](sim::BusDevice& d, SimClock& c) {
             xeg_reset_and_wait()(d, c);
             send(d, c, rtu("00 10 06 30 00 03 06 0C 80 1F 40 00 01"));
             c.advance_s(3);
         }},
        {"read 8 discrete inputs from 0x0000, id 2; reply 0x22 = HOLD and CHK1 on (example bits as printed)",
         [](sim::BusDevice& d, SimClock& c) { REQUIRE(d.control("inputs 0x22", c.now()).empty()); }},
        {"FC06 to nonexistent 0x0611 -> exception 02", nothing()},
        {"read exception status FC07 -> 02 emergency stop",
         [](sim::BusDevice& d, SimClock& c) { REQUIRE(d.control("alarm 7", c.now()).empty()); }},
        // excd203mb (ID 1)
        {"save after switching to Modbus mode, id 1: write 0x0303=0", nothing(), Expect::acknowledged},
        {"hdir 0x0000=1 (home direction reverse)", nothing()},
        {"solm+ 0x0014 (2 registers) = 800000 = 0x000C3500, high word first", nothing()},
        {"read rabs 0x0201 (2 registers) -> 0", nothing()},
        {"read rin 0x0203 -> 0x000F", nothing()},
        // wtec-485, Modbus-RTU (ID 1)
        {"initialize (home) 0x0100=1", nothing()},
        {"read init state 0x0200 -> 0 not initialized", nothing()},
        {"force 0x0103=80%", nothing()},
        {"force 0x0103=100%", nothing()},
        {"read force 0x0103", nothing(), Expect::acknowledged},
        {"position 0x0105=50", wtec_rtu_initialized()},
        {"read set position 0x0105", nothing(), Expect::acknowledged},
        {"read instant position 0x0204", nothing()},
        {"speed 0x0104=50%", nothing()},
        {"read speed 0x0104", nothing(), Expect::acknowledged},
        {"read grip state 0x0202 -> 2 object gripped",
         [](sim::BusDevice& d, SimClock& c) {
             wtec_rtu_initialized()(d, c);
             REQUIRE(d.control("object 40", c.now()).empty());
             send(d, c, rtu("01 06 01 05 00 64"));
             c.advance_s(1);
         }},
        {"init direction 0x0300=1 (open)", nothing()},
        {"save to flash 0x0302=1", nothing()},
        {"set device id 0x0303=5 (reply comes from the new id 5)", nothing()},
        {"emergency stop 0x0102=1", nothing()},
        // wtec-485, ASCII (address 01)
        {"A read firmware version", nothing()},
        {"$ read all station numbers (broadcast; every device answers)", nothing()},
        {"a enable(1)/release(0) motor", nothing()},
        {"B read homing parameters", nothing()},
        {"b write homing parameters", nothing()},
        {"C set peak (grip) current 0x3C", nothing()},
        {"D set target coordinate", wtec_ascii_homed(), Expect::corrected_d},
        {"d query in-position state -> 01 reached", wtec_ascii_homed()},
        {"E gripper action 1 grip (2 release, 3 toggle)", wtec_ascii_homed()},
        {"G reset (homing)", nothing()},
        {"g query homing state -> 01 done", wtec_ascii_homed()},
        {"I read running values",
         [](sim::BusDevice& d, SimClock& c) {
             wtec_ascii_homed()(d, c);
             send(d, c, ascii(wtec::encode_frame_body(
                            wtec::encode_command(1, wtec::GripperAction{wtec::GripAction::release}))));
             c.advance_s(1);
         }},
        {"i change station number 01 -> 0A (reply from the new address)", nothing()},
        {"P read PID", nothing()},
        {"p write PID", nothing()},
        {"N read gripper parameters",
         [](sim::BusDevice& d, SimClock& c) { send(d, c, ascii(">01n00005C443FFF0A119FE")); }},
        {"n write gripper parameters", nothing()},
        {"R read driver parameters", nothing()},
        {"r write driver parameters", nothing()},
        {"U save all parameters", nothing()},
        {"W read release current and speed", nothing()},
        {"w write release current and speed", nothing()},
        {"Z calibrate encoder", nothing(), Expect::no_reply},
    };
    return all;
}

std::unique_ptr<sim::BusDevice> device_for(const Vector& v) {
    if (v.device == "hiwin-xeg") return std::make_unique<sim::XegModel>(2, sim::XegOptions{});
    if (v.device == "excd203mb") return std::make_unique<sim::ExcdModel>(1, sim::ExcdOptions{});
    if (v.protocol == "modbus-rtu") return std::make_unique<sim::WtecRtuModel>(1, 20000);
    return std::make_unique<sim::WtecAsciiModel>(1, 20000);
}

protocol::Bytes request_bytes(const Vector& v) {
    return v.protocol == "wtec-ascii" ? ascii(v.request) : parse_hex(v.request);
}

std::string reply_text(const Vector& v, const protocol::Bytes& reply) {
    return v.protocol == "wtec-ascii" ? ascii_text(reply) : hex_of(reply);
}

std::string expected_text(const Vector& v) {
    return v.protocol == "wtec-ascii" ? *v.response : hex_of(parse_hex(*v.response));
}

}  // namespace

TEST_CASE("vectors: every serial example of the manuals replays against the models") {
    std::size_t replayed = 0;
    for (const auto& v : all_vectors()) {
        if (v.device != "hiwin-xeg" && v.device != "excd203mb" && v.device != "wtec-485") continue;
        INFO(v.device << " / " << v.what);
        const Case* found = nullptr;
        for (const auto& c : cases()) {
            if (c.what == v.what) found = &c;
        }
        REQUIRE_MESSAGE(found != nullptr, "no replay case for this vector");
        SimClock clock;
        const auto device = device_for(v);
        found->setup(*device, clock);
        device->advance(clock.now());
        const auto reply = device->on_frame(request_bytes(v), clock.now());
        switch (found->expect) {
            case Expect::exact:
                REQUIRE(v.response.has_value());
                REQUIRE_MESSAGE(reply.has_value(), "no reply");
                CHECK(reply_text(v, *reply) == expected_text(v));
                break;
            case Expect::no_reply:
                CHECK_FALSE(reply.has_value());
                break;
            case Expect::acknowledged:
                REQUIRE(reply.has_value());
                CHECK_MESSAGE(((*reply)[1] & 0x80) == 0, "exception reply " << hex_of(*reply));
                break;
            case Expect::corrected_d: {
                CHECK_FALSE(reply.has_value());
                const std::string d = wtec::encode_frame_body(wtec::encode_command(1, wtec::SetTarget{0x0001FFFF}));
                const auto corrected = device->on_frame(ascii(d), clock.now());
                REQUIRE(corrected.has_value());
                CHECK(ascii_text(*corrected) == *v.response);
                break;
            }
        }
        ++replayed;
    }
    CHECK(replayed == cases().size());
}

}  // namespace fieldbridge::test
