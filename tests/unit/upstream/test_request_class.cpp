#include <doctest/doctest.h>

#include "northbound/upstream/request_class.hpp"

using namespace fieldbridge;
using namespace fieldbridge::northbound::upstream;
using protocol::Bytes;

namespace {
RequestClass of(const Bytes& pdu) {
    const Classified c = classify(pdu);
    REQUIRE(c.request.has_value());
    return *c.request;
}
}  // namespace

TEST_CASE("reads are on-demand, every write is a command, stops are urgent") {
    CHECK(of({0x03, 0x08, 0x89, 0x00, 0x01}).priority == engine::Priority::on_demand);
    CHECK(of({0x01, 0x00, 0x00, 0x00, 0x08}).priority == engine::Priority::on_demand);
    CHECK(of({0x05, 0x00, 0x01, 0xFF, 0x00}).priority == engine::Priority::command);
    CHECK(of({0x0F, 0x00, 0x00, 0x00, 0x03, 0x01, 0x05}).priority == engine::Priority::command);
    // seed 004 3.2.2: global speed is a plain write, still a command (spec §3 rule 2).
    const RequestClass speed = of({0x06, 0x4E, 0xE8, 0x00, 0x64});
    CHECK(speed.priority == engine::Priority::command);
    CHECK_FALSE(speed.urgent);
    CHECK(of({0x06, 0x4E, 0x20, 0x00, 0x01}).urgent);   // stop
    CHECK(of({0x06, 0x4E, 0x21, 0x00, 0x01}).urgent);   // pause
    CHECK(of({0x06, 0x4E, 0x24, 0x00, 0x01}).urgent);   // stop button
    CHECK_FALSE(of({0x06, 0x4E, 0x23, 0x00, 0x01}).urgent);  // start button
    // An unknown function code is forwarded; 0x2B is a read in the Modbus spec.
    CHECK(of({0x2B, 0x0E, 0x01, 0x00}).priority == engine::Priority::on_demand);
    CHECK(of({0x42, 0x01}).priority == engine::Priority::command);
}

TEST_CASE("counter indirection: select begins, block read finishes") {
    const RequestClass select = of({0x10, 0x08, 0x83, 0x00, 0x02, 0x04, 0x00, 0x00, 0x00, 0x01});
    CHECK(select.role(Resource::counter_read) == Role::begin);
    CHECK(select.role(Resource::source_upload) == Role::none);
    CHECK(of({0x03, 0x08, 0x83, 0x00, 0x06}).role(Resource::counter_read) == Role::finish);
    CHECK(of({0x03, 0x08, 0x87, 0x00, 0x02}).role(Resource::counter_read) == Role::finish);
    CHECK(of({0x04, 0x08, 0x85, 0x00, 0x02}).role(Resource::counter_read) == Role::finish);
    // The counter list ends at 0x0882 and the mode is at 0x0889: neither touches it.
    CHECK(of({0x03, 0x08, 0x81, 0x00, 0x02}).role(Resource::counter_read) == Role::none);
    CHECK(of({0x03, 0x08, 0x89, 0x00, 0x01}).role(Resource::counter_read) == Role::none);
    CHECK(of({0x03, 0x08, 0x82, 0x00, 0x02}).role(Resource::counter_read) == Role::finish);
    // FC17 selecting and reading at once is a whole sequence: it only waits.
    CHECK(of({0x17, 0x08, 0x83, 0x00, 0x06, 0x08, 0x83, 0x00, 0x02, 0x04, 0x00, 0x00, 0x00, 0x01})
              .role(Resource::counter_read) == Role::use);
    // Counter modify (0x4E52) is a different block.
    CHECK_FALSE(of({0x10, 0x4E, 0x52, 0x00, 0x06, 0x0C, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 8}).touches_any());
}

TEST_CASE("data-source view and upload") {
    CHECK(of({0x06, 0x75, 0x30, 0x00, 0x64}).role(Resource::source_view) == Role::begin);
    CHECK(of({0x03, 0x75, 0x31, 0x00, 0x01}).role(Resource::source_view) == Role::finish);
    const RequestClass setup = of({0x10, 0x75, 0x32, 0x00, 0x03, 0x06, 0x00, 0x64, 0x00, 0x06, 0x00, 0x23});
    CHECK(setup.role(Resource::source_upload) == Role::begin);
    CHECK(setup.role(Resource::source_view) == Role::none);
    CHECK(of({0x10, 0x75, 0x35, 0x00, 0x02, 0x04, 0x00, 0x02, 0x00, 0x01}).role(Resource::source_upload) ==
          Role::use);
    CHECK(of({0x10, 0x9C, 0x3F, 0x00, 0x02, 0x04, 0, 0, 0, 1}).role(Resource::source_upload) == Role::use);
    CHECK(of({0x10, 0x9C, 0x41, 0x00, 0x02, 0x04, 0, 0, 0, 1}).role(Resource::source_upload) == Role::none);
    CHECK(of({0x03, 0x75, 0x33, 0x00, 0x01}).role(Resource::source_upload) == Role::use);
}

TEST_CASE("PDUs no function code can carry are answered locally") {
    CHECK_FALSE(classify(Bytes{}).request);
    CHECK(classify(Bytes{}).local.refusal == protocol::GatewayRefusal::not_a_function);
    CHECK(classify(Bytes{0x00, 0x01}).local.refusal == protocol::GatewayRefusal::not_a_function);
    CHECK(classify(Bytes{0x83, 0x02}).local.refusal == protocol::GatewayRefusal::not_a_function);
    const Classified zero = classify(Bytes{0x03, 0x08, 0x89, 0x00, 0x00});
    CHECK_FALSE(zero.request);
    CHECK(zero.local.refusal == protocol::GatewayRefusal::bad_value);
    const Classified short_write = classify(Bytes{0x10, 0x08, 0x83, 0x00, 0x02, 0x04, 0x00});
    CHECK_FALSE(short_write.request);
    CHECK(short_write.local.refusal == protocol::GatewayRefusal::bad_value);
}

TEST_CASE("each resource is named with the registers of its block (r6_sequences)") {
    CHECK(to_string(Resource::counter_read) == "counter read (0x0883-0x0888)");
    CHECK(to_string(Resource::source_view) == "data-source view (0x7530-0x7531)");
    CHECK(to_string(Resource::source_upload) == "data-source upload (0x7532-0x9C40)");
}
