// The edge node's own metrics (northbound/sparkplug_node/node_metrics.*).
#include <doctest/doctest.h>

#include "northbound/sparkplug_node/node_metrics.hpp"

namespace {
namespace sp = fieldbridge::northbound::sparkplug;
namespace sn = fieldbridge::northbound::sparkplug_node;
using T = sp::DataType;

const sp::Metric* node_metric_named(const std::vector<sp::Metric>& metrics, const std::string& name) {
    for (const auto& m : metrics) {
        if (m.name == name) return &m;
    }
    return nullptr;
}

sn::NodeSnapshot snapshot() {
    sn::NodeSnapshot s;
    s.version = "0.3.0";
    s.json_bridge = "connected";
    s.commands_accepted = 3;
    s.commands_refused = 1;
    s.lines.push_back({"line-a", true, 1200, 4, 31.5, 87.5});
    s.upstreams.push_back({"r6", "up"});
    return s;
}

}  // namespace

TEST_CASE("every node metric is named in its folder, typed and valued") {
    const auto metrics = sn::node_metrics(snapshot(), 1700000000000);
    struct Expected {
        const char* name;
        T type;
        sp::Value value;
    };
    const Expected expected[] = {
        {"Properties/Software Version", T::string, std::string("0.3.0")},
        {"Properties/JSON Bridge", T::string, std::string("connected")},
        {"Properties/Commands Accepted", T::uint64, std::uint64_t{3}},
        {"Properties/Commands Refused", T::uint64, std::uint64_t{1}},
        {"Lines/line-a/Up", T::boolean, true},
        {"Lines/line-a/Requests", T::uint64, std::uint64_t{1200}},
        {"Lines/line-a/Timeouts", T::uint64, std::uint64_t{4}},
        {"Lines/line-a/Transactions Per Second", T::float64, 31.5},
        {"Lines/line-a/Utilisation Pct", T::float64, 87.5},
        {"Upstreams/r6/Link", T::string, std::string("up")},
    };
    CHECK(metrics.size() == std::size(expected));
    for (const Expected& e : expected) {
        CAPTURE(e.name);
        const sp::Metric* m = node_metric_named(metrics, e.name);
        REQUIRE(m != nullptr);
        CHECK(m->datatype == e.type);
        CHECK(m->value == e.value);
        CHECK(m->timestamp == 1700000000000u);
        CHECK_FALSE(m->alias.has_value());
    }
}

TEST_CASE("only the metrics whose value moved are changed") {
    const auto before = sn::node_metrics(snapshot(), 1);
    auto next = snapshot();
    next.commands_refused = 2;
    next.lines[0].up = false;
    const auto changed = sn::changed_node_metrics(before, sn::node_metrics(next, 2));
    REQUIRE(changed.size() == 2);
    CHECK(changed[0].name == "Properties/Commands Refused");
    CHECK(changed[1].name == "Lines/line-a/Up");
    CHECK(sn::changed_node_metrics(before, sn::node_metrics(snapshot(), 3)).empty());
    // A new line: all of its metrics.
    next = snapshot();
    next.lines.push_back({"line-b", true, 0, 0, 0, 0});
    CHECK(sn::changed_node_metrics(before, sn::node_metrics(next, 4)).size() == 5);
}
