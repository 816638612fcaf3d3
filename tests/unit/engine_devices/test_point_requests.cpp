// Requests for named points: all-or-nothing writes, merged reads.
#include <doctest/doctest.h>

#include <string>
#include <vector>

#include "engine/points/point_requests.hpp"
#include "vectors.hpp"
#include "point_builders.hpp"

namespace {

namespace fc = fieldbridge::core;
namespace fp = fieldbridge::protocol;
namespace pts = fieldbridge::engine::points;
using fieldbridge::test::hex;

using fieldbridge::test::point_def;

fc::PointModel thermostat() {
    fc::PointModel m;
    m.points.push_back(point_def("temperature", fc::RegisterTable::input, 0x0000, fc::PointType::float32));
    m.points.push_back(point_def("humidity", fc::RegisterTable::input, 0x0002, fc::PointType::uint16));
    m.points.push_back(point_def("energy", fc::RegisterTable::input, 0x0010, fc::PointType::int32));
    fc::PointDef setpoint = point_def("setpoint", fc::RegisterTable::holding, 0x0100, fc::PointType::int16, true);
    setpoint.scale = 0.1;
    setpoint.min = 5.0;
    setpoint.max = 30.0;
    m.points.push_back(setpoint);
    fc::PointDef mode = point_def("mode", fc::RegisterTable::holding, 0x0101, fc::PointType::uint16, true);
    mode.labels = {{0, "off"}, {1, "heat"}, {2, "cool"}};
    m.points.push_back(mode);
    fc::PointDef eco = point_def("eco", fc::RegisterTable::holding, 0x0102, fc::PointType::boolean, true);
    eco.bit = 4;
    m.points.push_back(eco);
    m.points.push_back(point_def("relay", fc::RegisterTable::coils, 0x0007, fc::PointType::boolean, true));
    m.points.push_back(point_def("limit", fc::RegisterTable::holding, 0x0200, fc::PointType::float64, true));
    m.points.push_back(point_def("serial", fc::RegisterTable::holding, 0x0300, fc::PointType::uint32));
    m.points.push_back(point_def("door", fc::RegisterTable::discrete_inputs, 0x0003, fc::PointType::boolean, true));
    return m;
}

std::vector<std::string> pdus(const pts::PointRequests& r) {
    std::vector<std::string> out;
    for (const fp::Request& q : r.requests) out.push_back(hex(fp::encode_request(q)));
    return out;
}

}  // namespace

TEST_CASE("point requests: writes in order, one request per point, by its table and width") {
    const fc::PointModel m = thermostat();
    const std::vector<pts::PointWrite> writes{{"setpoint", 21.5},
                                              {"mode", std::string{"heat"}},
                                              {"eco", true},
                                              {"relay", true},
                                              {"limit", 1.0}};
    const pts::PointRequests r = pts::write_requests(m, writes);
    REQUIRE(r.ok());
    CHECK(pdus(r) == std::vector<std::string>{
                         "06 01 00 00 D7",                                 // 215 at scale 0.1
                         "06 01 01 00 01",                                 // heat
                         "16 01 02 FF EF 00 10",                           // FC22: bit 4 set, others kept
                         "05 00 07 FF 00",                                 // coil on
                         "10 02 00 00 04 08 3F F0 00 00 00 00 00 00",  // float64 1.0
                     });
    const std::vector<pts::PointWrite> off{{"eco", false}};
    CHECK(pdus(pts::write_requests(m, off)) == std::vector<std::string>{"16 01 02 FF EF 00 00"});
}

TEST_CASE("point requests: all or nothing, the error names the point") {
    const fc::PointModel m = thermostat();
    const auto refused = [&m](std::vector<pts::PointWrite> writes) { return pts::write_requests(m, writes); };

    auto r = refused({{"setpoint", 21.5}, {"fan", true}});
    CHECK(r.requests.empty());
    CHECK(r.point == "fan");
    CHECK(r.error == "point 'fan': the device has no such point; its points are listed in its `fields`");

    r = refused({{"setpoint", 21.5}, {"serial", std::int64_t{7}}});
    CHECK(r.requests.empty());
    CHECK(r.point == "serial");
    CHECK(r.error == "point 'serial': read-only; only points marked `writable` can be written");

    r = refused({{"door", true}});  // writable in the file, but a discrete input cannot be written
    CHECK(r.point == "door");
    CHECK_FALSE(r.ok());

    r = refused({{"mode", std::string{"heat"}}, {"setpoint", 31.0}});
    CHECK(r.requests.empty());
    CHECK(r.error == "point 'setpoint': 31 is above the maximum 30");

    r = refused({{"setpoint", std::string{"warm"}}});
    CHECK(r.error == "point 'setpoint': it takes a number, not a string");

    r = refused({{"mode", std::string{"dry"}}});
    CHECK(r.point == "mode");
    CHECK(r.error.find("not one of its labels") != std::string::npos);
}

TEST_CASE("point requests: reads merged where adjacent, by table then address") {
    const fc::PointModel m = thermostat();
    const std::vector<std::string> names{"setpoint", "humidity", "temperature", "mode", "energy", "relay", "door"};
    const pts::PointRequests r = pts::read_requests(m, names);
    REQUIRE(r.ok());
    CHECK(pdus(r) == std::vector<std::string>{
                         "01 00 07 00 01",  // relay
                         "02 00 03 00 01",  // door
                         "03 01 00 00 02",  // setpoint + mode
                         "04 00 00 00 03",  // temperature + humidity
                         "04 00 10 00 02",  // energy: not adjacent
                     });
    const std::vector<std::string> twice{"temperature", "temperature"};
    CHECK(pdus(pts::read_requests(m, twice)) == std::vector<std::string>{"04 00 00 00 02"});
    const std::vector<std::string> unknown{"temperature", "pressure"};
    const pts::PointRequests bad = pts::read_requests(m, unknown);
    CHECK(bad.requests.empty());
    CHECK(bad.point == "pressure");
    CHECK(pts::read_requests(m, std::vector<std::string>{}).requests.empty());
}

TEST_CASE("point requests: a merged read stays within 125 registers") {
    fc::PointModel m;
    m.points.push_back(point_def("a", fc::RegisterTable::holding, 0, fc::PointType::string));
    m.points.back().count = 100;
    m.points.push_back(point_def("b", fc::RegisterTable::holding, 100, fc::PointType::string));
    m.points.back().count = 30;
    const std::vector<std::string> names{"a", "b"};
    CHECK(pdus(pts::read_requests(m, names)) == std::vector<std::string>{"03 00 00 00 64", "03 00 64 00 1E"});
}
