// The metric catalogue (northbound/sparkplug/metric_catalogue.*): every field of a
// device's JSON state (northbound/mqtt/payloads.cpp) is a metric of the same name and
// value, for a generic device with points and for each built-in type; aliases; DDATA
// of what changed, with deadbands.
#include <doctest/doctest.h>

#include <cmath>
#include <set>
#include <vector>

#include "engine/profiles/profile_factory.hpp"
#include "northbound/mqtt/agent_source.hpp"
#include "northbound/mqtt/payloads.hpp"
#include "northbound/sparkplug/metric_catalogue.hpp"
#include "northbound/upstream/r6_state.hpp"
#include "point_builders.hpp"

namespace {

namespace fe = fieldbridge::engine;
namespace fm = fieldbridge::northbound::mqtt;
namespace sp = fieldbridge::northbound::sparkplug;
namespace core = fieldbridge::core;
using nlohmann::json;
using T = sp::DataType;
using fieldbridge::test::point_def;

// Every register and bit of the four tables from 0 to 0x1FFF, with values that vary.
void fill(fe::RegisterImage& image, std::uint16_t seed) {
    std::vector<std::uint16_t> words(0x2000);
    std::vector<std::uint16_t> bits(0x2000);
    for (std::size_t i = 0; i < words.size(); ++i) {
        words[i] = static_cast<std::uint16_t>((i * 37 + seed) % 1000);
        bits[i] = static_cast<std::uint16_t>((i + seed) % 2);
    }
    const auto now = fe::Clock::now();
    image.update(fe::Table::holding, 0, words, now);
    image.update(fe::Table::input, 0, words, now);
    image.update(fe::Table::coils, 0, bits, now);
    image.update(fe::Table::discrete_inputs, 0, bits, now);
}

// The metric's value as the JSON state would show it.
json as_json(const sp::Metric& metric) {
    const T type = *metric.datatype;
    if (const auto* i = std::get_if<std::uint64_t>(&metric.value)) {
        switch (type) {
        case T::int8:
        case T::int16:
        case T::int32:
        case T::int64:
            return static_cast<std::int64_t>(*i);
        default:
            return *i;
        }
    }
    if (const auto* f = std::get_if<float>(&metric.value)) return static_cast<double>(*f);
    if (const auto* d = std::get_if<double>(&metric.value)) return *d;
    if (const auto* b = std::get_if<bool>(&metric.value)) return *b;
    if (const auto* s = std::get_if<std::string>(&metric.value)) return *s;
    return nullptr;
}

const sp::Metric* by_name(const std::vector<sp::Metric>& metrics, const std::string& name) {
    for (const auto& m : metrics) {
        if (m.name == name) return &m;
    }
    return nullptr;
}

bool same(const json& field, const sp::Metric& metric) {
    const json value = as_json(metric);
    if (field.is_number_float() && value.is_number()) {
        if (*metric.datatype == T::float32) {
            return static_cast<float>(field.get<double>()) == static_cast<float>(value.get<double>());
        }
        return field.get<double>() == value.get<double>();
    }
    return field == value;
}

// Every field of the JSON state has a metric of that name (a list: `<name>/<i>`) and
// value, and the catalogue has no metric the state lacks.
void check_fields_match(const fm::SourceState& state, const core::PointModel* points, const char* type) {
    sp::MetricCatalogue catalogue;
    catalogue.add_device(sp::DeviceShape{"dev", points, state.decoded, {}, {}});
    const auto birth = catalogue.birth_metrics("dev", state.decoded, 1000, true);
    const json j = fm::state_payload("dev", type, state, fm::ClockPair::now());
    REQUIRE_FALSE(j["fields"].empty());
    std::size_t expected = 0;
    for (const auto& [name, value] : j["fields"].items()) {
        CAPTURE(name);
        if (value.is_array()) {
            for (std::size_t i = 0; i < value.size(); ++i) {
                const sp::Metric* m = by_name(birth, name + "/" + std::to_string(i));
                REQUIRE(m != nullptr);
                CHECK(*m->datatype == T::float64);
                CHECK(same(value[i], *m));
                ++expected;
            }
            continue;
        }
        const sp::Metric* m = by_name(birth, name);
        REQUIRE(m != nullptr);
        CHECK(same(value, *m));
        ++expected;
    }
    CHECK(birth.size() == expected);
    for (const auto& m : birth) {
        CHECK(m.alias.has_value());
        CHECK(m.timestamp == 1000u);
    }
}

core::PointModel generic_points() {
    using core::PointType;
    using core::RegisterTable;
    core::PointModel model;
    auto temperature = point_def("temperature", RegisterTable::input, 0, PointType::int16);
    temperature.scale = 0.1;
    temperature.unit = "°C";
    temperature.deadband = 0.5;
    auto mode = point_def("mode", RegisterTable::holding, 1, PointType::uint16);
    mode.labels = {{0, "off"}, {37, "heat"}, {38, "cool"}};  // the image holds 37 there
    mode.writable = true;
    auto setpoint = point_def("setpoint", RegisterTable::holding, 2, PointType::float32);
    setpoint.writable = true;
    setpoint.unit = "°C";
    auto counter = point_def("counter", RegisterTable::input, 4, PointType::uint32);
    auto total = point_def("total", RegisterTable::input, 6, PointType::int64);
    auto ratio = point_def("ratio", RegisterTable::input, 10, PointType::float64);
    auto running = point_def("running", RegisterTable::coils, 0, PointType::boolean);
    auto alarm_bit = point_def("alarm_bit", RegisterTable::holding, 20, PointType::boolean);
    alarm_bit.bit = 3;
    auto label = point_def("label", RegisterTable::holding, 30, PointType::string);
    label.count = 2;
    auto level = point_def("level", RegisterTable::holding, 40, PointType::uint16);
    auto offset_value = point_def("offset_value", RegisterTable::holding, 41, PointType::int32);
    auto version = point_def("version", RegisterTable::input, 50, PointType::uint32);
    version.format = core::PointFormat::hex;  // a text, "0x...": a String metric
    model.points = {temperature, mode,  setpoint, counter,      total,  ratio,
                    running,     alarm_bit, label, level, offset_value, version};
    return model;
}

fm::SourceState generic_state(const core::PointModel& points, std::uint16_t seed) {
    fe::ProfileOptions options;
    options.points = points;
    auto profile = fe::make_profile(fe::DeviceType::modbus, options);
    fe::RegisterImage image;
    fill(image, seed);
    return fm::image_state(*profile, image, true);
}

}  // namespace

TEST_CASE("sparkplug catalogue: a generic device's JSON fields are its metrics, datatypes from the points") {
    const core::PointModel points = generic_points();
    const fm::SourceState state = generic_state(points, 0);
    check_fields_match(state, &points, "modbus");

    sp::MetricCatalogue catalogue(5);
    catalogue.add_device(sp::DeviceShape{"plc", &points, state.decoded, {}, {}});
    const auto& metrics = catalogue.metrics("plc");
    std::vector<std::pair<std::string, T>> got;
    for (const auto& m : metrics) got.emplace_back(m.name, m.datatype);
    // Points in the model's order; an enum point is its label (String) and its code.
    CHECK(got == std::vector<std::pair<std::string, T>>{
                     {"temperature", T::float64}, {"mode", T::string}, {"mode_code", T::uint16},
                     {"setpoint", T::float32}, {"counter", T::uint32}, {"total", T::int64},
                     {"ratio", T::float64}, {"running", T::boolean}, {"alarm_bit", T::boolean},
                     {"label", T::string}, {"level", T::uint16}, {"offset_value", T::int32},
                     {"version", T::string}});
    // Aliases from the first one given, in order; unique.
    for (std::size_t i = 0; i < metrics.size(); ++i) CHECK(metrics[i].alias == 5 + i);

    const auto birth = catalogue.birth_metrics("plc", state.decoded, 42, true);
    const sp::Metric* temperature = by_name(birth, "temperature");
    REQUIRE(temperature != nullptr);
    CHECK(temperature->properties == std::vector<sp::Property>{{"engUnit", T::string, std::string("°C")}});
    const sp::Metric* setpoint = by_name(birth, "setpoint");
    REQUIRE(setpoint != nullptr);
    CHECK(setpoint->properties == std::vector<sp::Property>{{"engUnit", T::string, std::string("°C")},
                                                            {"writable", T::boolean, true}});
    const sp::Metric* mode_code = by_name(birth, "mode_code");
    REQUIRE(mode_code != nullptr);
    CHECK(mode_code->properties == std::vector<sp::Property>{{"writable", T::boolean, true}});
    CHECK(by_name(birth, "mode")->properties.empty());
    // Without aliases, names only.
    for (const auto& m : catalogue.birth_metrics("plc", state.decoded, 42, false)) CHECK_FALSE(m.alias.has_value());
}

TEST_CASE("sparkplug catalogue: each built-in type's JSON fields are its metrics") {
    for (const auto type : {fe::DeviceType::hiwin_xeg, fe::DeviceType::excd203mb, fe::DeviceType::wtec_rtu,
                            fe::DeviceType::wtec_ascii}) {
        CAPTURE(static_cast<int>(type));
        fe::ProfileOptions options;
        options.wtec_stroke = 10000;
        auto profile = fe::make_profile(type, options);
        fe::RegisterImage image;
        fill(image, 3);
        const fm::SourceState state = fm::image_state(*profile, image, true);
        check_fields_match(state, nullptr, "built-in");
    }
    fm::SourceState r6;
    r6.online = true;
    fe::RegisterImage image;
    fill(image, 1);
    r6.decoded = fieldbridge::northbound::upstream::decode_r6_state(image);
    REQUIRE(r6.decoded.find("axes_deg") != nullptr);
    check_fields_match(r6, nullptr, "r6");
}

TEST_CASE("sparkplug catalogue: DDATA carries what changed beyond the deadband, by alias") {
    const core::PointModel points = generic_points();
    sp::MetricCatalogue catalogue;
    fm::SourceState before = generic_state(points, 0);
    catalogue.add_device(sp::DeviceShape{"plc", &points, before.decoded, {}, {}});
    CHECK(catalogue.changed_metrics("plc", before.decoded, before.decoded, 7, true).empty());

    fe::DecodedState after = before.decoded;
    const auto set = [&](const std::string& name, fe::FieldValue value) {
        for (auto& f : after.fields) {
            if (f.name == name) f.value = std::move(value);
        }
    };
    const double t0 = std::get<double>(before.decoded.find("temperature")->value);
    set("temperature", t0 + 0.3);  // under the 0.5 deadband: not a change
    set("level", std::int64_t{999});
    auto changed = catalogue.changed_metrics("plc", before.decoded, after, 7, true);
    REQUIRE(changed.size() == 1);
    const sp::CatalogueMetric* level = catalogue.find("plc", sp::MetricReference{"level", std::nullopt});
    REQUIRE(level != nullptr);
    CHECK(changed[0].alias == level->alias);
    CHECK_FALSE(changed[0].name.has_value());
    CHECK_FALSE(changed[0].datatype.has_value());
    CHECK(changed[0].timestamp == 7u);
    CHECK(std::get<std::uint64_t>(changed[0].value) == 999);
    set("temperature", t0 + 0.6);
    changed = catalogue.changed_metrics("plc", before.decoded, after, 8, false);
    REQUIRE(changed.size() == 2);
    CHECK(changed[0].name == "temperature");
    CHECK(changed[1].name == "level");
}

TEST_CASE("sparkplug catalogue: aliases are unique across devices and stable across re-adding") {
    const core::PointModel points = generic_points();
    const fm::SourceState state = generic_state(points, 0);
    sp::MetricCatalogue catalogue;
    catalogue.add_device(sp::DeviceShape{"a", &points, state.decoded, {}, {}});
    catalogue.add_device(sp::DeviceShape{"b", &points, state.decoded, {}, {}});
    std::set<std::uint64_t> aliases;
    for (const auto* device : {"a", "b"}) {
        for (const auto& m : catalogue.metrics(device)) CHECK(aliases.insert(m.alias).second);
    }
    const auto before = catalogue.metrics("a").front().alias;
    catalogue.remove_device("a");
    CHECK(catalogue.metrics("a").empty());
    CHECK_FALSE(catalogue.add_device(sp::DeviceShape{"b", &points, state.decoded, {}, {}}));  // nothing new
    CHECK(catalogue.add_device(sp::DeviceShape{"a", &points, state.decoded, {}, {}}));
    CHECK(catalogue.metrics("a").front().alias == before);
    // A field the catalogue does not know: not covered until added again.
    fe::DecodedState more = state.decoded;
    more.fields.push_back(fe::Field{"extra", true, ""});
    CHECK_FALSE(catalogue.covers("a", more));
    CHECK(catalogue.add_device(sp::DeviceShape{"a", &points, more, {"extra"}, {}}));
    CHECK(catalogue.covers("a", more));
    const auto* extra = catalogue.find("a", sp::MetricReference{"extra", std::nullopt});
    REQUIRE(extra != nullptr);
    CHECK(extra->writable);
    CHECK(catalogue.find("a", sp::MetricReference{std::nullopt, extra->alias}) == extra);
    CHECK(catalogue.find("a", sp::MetricReference{"nope", std::nullopt}) == nullptr);
}
