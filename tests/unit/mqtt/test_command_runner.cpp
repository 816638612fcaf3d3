// What a command's Modbus answer means for its MQTT result (docs/mqtt.md, "cmd/result").
#include <doctest/doctest.h>

#include "northbound/mqtt/command_runner.hpp"

namespace {

namespace fm = fieldbridge::northbound::mqtt;
namespace fp = fieldbridge::protocol;

fp::Response exception(fp::ExceptionCode code) { return fp::ExceptionResponse{fp::fc::write_single_register, code}; }

}  // namespace

TEST_CASE("command outcome: a WTEC ASCII 0x04 is a command the gripper did not execute") {
    const auto refused = fm::outcome_of(exception(fp::ExceptionCode::server_device_failure), "wtec-ascii");
    CHECK_FALSE(refused.ok);
    CHECK(refused.error == "not_executed");
    CHECK(refused.exception == fp::ExceptionCode::server_device_failure);
    CHECK(refused.message.find("did not execute") != std::string::npos);
    CHECK(refused.message.find("op init") != std::string::npos);
    // Elsewhere 0x04 is the device's own exception; 0x0B stays "no answer" everywhere.
    for (const char* type : {"hiwin-xeg", "wtec-rtu", "excd203mb", "modbus"}) {
        CHECK(fm::outcome_of(exception(fp::ExceptionCode::server_device_failure), type).error == "device_exception");
    }
    CHECK(fm::outcome_of(exception(fp::ExceptionCode::gateway_target_failed), "wtec-ascii").error == "no_answer");
    CHECK(fm::outcome_of(fp::WriteSingleResponse{fp::fc::write_single_register, 0x0105, 30}, "wtec-ascii").ok);
}
