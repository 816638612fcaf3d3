// The bounded outbox: retained values coalesce, events are dropped oldest first.
#include <doctest/doctest.h>

#include "northbound/mqtt/outbox.hpp"

namespace fm = fieldbridge::northbound::mqtt;

TEST_CASE("outbox: a retained message replaces the one waiting for its topic, and moves to the back") {
    fm::Outbox box(8);
    box.put({"p/a/state", "1", 1, true});
    box.put({"p/a/alarm", "event", 1, false});
    box.put({"p/a/state", "2", 1, true});
    CHECK(box.size() == 2);
    CHECK(box.superseded() == 1);
    CHECK(box.take()->payload == "event");
    CHECK(box.take()->payload == "2");
    CHECK_FALSE(box.take());
}

TEST_CASE("outbox: events are kept in order; when full the oldest goes and is counted") {
    fm::Outbox box(3);
    for (int i = 0; i < 5; ++i) box.put({"p/d/cmd/result", std::to_string(i), 1, false});
    CHECK(box.size() == 3);
    CHECK(box.dropped() == 2);
    CHECK(box.take()->payload == "2");
    box.put_first({"p/status", "online", 1, true});
    CHECK(box.take()->payload == "online");
    CHECK(box.take()->payload == "3");
}
